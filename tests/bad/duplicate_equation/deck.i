begin contact definition
  begin enforcement gap
    Enforcement For Energy = Gap_Conductance H = 10
    Enforcement For Energy = Contact_Resistance H = 20
  end
end
