begin contact definition main
  skin all blocks = on
  begin search options
    tangential tolerance = -1e-3
  end
end
