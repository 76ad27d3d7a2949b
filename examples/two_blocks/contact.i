# Two blocks meshed apart meet at z = 1 (6x6 faces below, 4x4 above).
# The interface surfaces come from side sets; the lid's top is split off by normal;
# Skin All Blocks, placed last, makes one surface per block from the faces left over.
begin contact definition two_blocks
  contact surface interface_base contains base_top
  contact surface interface_lid contains surface_2

  begin contact surface lid_outside
    block = lid
    remove surface = lid_bottom
    subset top with normal 0 0 1
  end

  skin all blocks = on exclude lid
end
