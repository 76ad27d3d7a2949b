begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = Constant H = 10
    Gap Conductance Coefficient = Gas_Gap K = abc Min_Gap = -1
    Gap Conductance Coefficient = Table Of Gapp = 0 1
    Gap Conductance Coefficient = Gas_Gap K = 0.1 K = 0.2
  end
end
