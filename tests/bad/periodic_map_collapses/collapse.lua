function centre(x, y, z)
  return 0.5
end
