-- conductance in W/m2K
function h(gap, temp_a, temp_b)
  return 10 +
end
