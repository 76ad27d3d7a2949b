begin contact definition main
  skin all blocks = on
  begin search options
    normal tolerance = 1.0e-3
    tangential tolerance = small
    search update frequency = 2.5
  end
end
