begin contact definition
  begin enforcement gap
    Enforcement For Energy = Gap_Conductance Hh = 5
  end
  begin enforcement tie
    Enforcement For Energy = Tied Multiplier = Dual
    Side B Variable temperature To temperature
  end
end
