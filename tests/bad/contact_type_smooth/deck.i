begin contact definition
  BEGIN CONTACT SURFACE surf1
    BLOCK = block_1
    CONTACT TYPE = SMOOTH
  END
end
