begin contact definition
  skin all blocks = on
end
