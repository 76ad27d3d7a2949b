begin contact definition main
  skin all blocks = on
  restrict contact to subdomain defined by radius 0 and point 0 0 0
end
