begin contact definition main
  skin all blocks = on
  begin search options
    buffer factor = -0.5
  end
end
