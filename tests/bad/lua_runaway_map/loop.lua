function fx(x, y, z)
  while true do end
end
