begin contact definition main
  begin enforcement lm
    enforcement for energy = tied
    slave variable temperature to temperature
  end
end
