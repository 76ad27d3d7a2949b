begin contact definition main
  skin all blocks = on
  opposed normal threshold angle = 45
end
