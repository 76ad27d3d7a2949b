begin contact definition
  contact surface left contains left_blok
  begin contact surface right
    block = block_20
    surface = interface_b
  end
end
