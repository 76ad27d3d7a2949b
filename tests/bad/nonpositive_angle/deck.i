begin contact definition main
  begin contact surface outer
    include all blocks
    auto subset faces angle = 0
  end
end
