begin contact definition
  begin enforcement gap
    Enforcement For Enregy = Gap_Conductance H = 10
  end
end
