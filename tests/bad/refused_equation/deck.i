begin contact definition
  begin enforcement electric
    Enforcement For Voltage = Tied_Voltage
    Enforcement For Porous_Species Tied_Species
  end
end
