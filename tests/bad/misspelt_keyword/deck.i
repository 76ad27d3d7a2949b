begin contact definition main
  Contact Surfce top Contains block_1
  Skin All Blocks = On
end
