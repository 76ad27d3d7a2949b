begin contact definition
  begin enforcement gap
    enforcement for energy = gap_conductance
    Gap Conductance Coefficient = Gas_Gapp K = 0.025
  end
end
