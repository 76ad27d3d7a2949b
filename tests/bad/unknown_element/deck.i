begin contact definition
  begin contact surface corner
    element = 100 999
  end
end
