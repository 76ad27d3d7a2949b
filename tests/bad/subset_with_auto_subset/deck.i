begin contact definition main
  begin contact surface outer
    block = block_1
    subset lid with normal 0 0 1
    auto subset walls number of subsets 4
  end
end
