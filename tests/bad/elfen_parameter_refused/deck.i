begin contact definition
  skin all blocks
  begin search options
    Buffer_factor = 1.0
    Corner_region_size = 0.02
    Print_search = 1
  end
end
