begin contact definition main
  skin all blocks = on
  update search every 0 steps
  begin search options
    search update frequency = 0
  end
end
