-- x of the periodic image
function shift_x(x, y, z)
  return x +
end
