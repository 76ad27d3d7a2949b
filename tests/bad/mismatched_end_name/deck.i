begin contact definition main
  begin contact surface top
    block = block_1
  end contact surface bottom
end contact definition main
