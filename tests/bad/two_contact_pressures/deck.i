begin contact definition
  begin enforcement gap
    Enforcement For Energy = Gap_Conductance
    Gap Conductance Coefficient = CMY K_A = 16 K_B = 200 Slope = 0.1 Roughness = 1e-6 Hardness = 3e9
    Contact Surface Pressure = Constant Value = 5e5
    Contact Pressure = 4e5
  end
end
