begin contact definition
  begin enforcement electric
    Enforcement For Voltage = Tied_Voltage
    Enforcement For Species Tied_Species
  end
end
