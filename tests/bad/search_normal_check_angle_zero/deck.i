begin contact definition main
  skin all blocks = on
  begin search options
    normal check angle = 0
  end
end
