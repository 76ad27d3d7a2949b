begin contact definition main
  skin all blocks = on
  begin interaction defaults
    general contact = on
  end
  begin search options
    normal tolerance = -0.001
  end
end
