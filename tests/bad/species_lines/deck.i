begin contact definition
  contact surface a contains surface_1
  contact surface b contains surface_2
  begin enforcement thermal
    enforcement for energy = tied_temperature
    partition coefficient = 2
  end
  begin enforcement mass
    enforcement for species = tied_species
    partition coefficient = -0.5
    offset species = constant value = 1e400
  end
end
