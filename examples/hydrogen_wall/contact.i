# The coating's back face against the substrate's front face, meshed apart: the wall
# conducts heat across it (a perfect thermal joint) and hydrogen with the partition
# coefficient of the two materials, c_coating = K c_steel (K = S_coating / S_steel, the
# ratio of their solubilities). The hydrogen tie is a dual mortar one: its multipliers
# carry the flux whatever D(T) does (`tied_species`, a Nitsche tie weighing the flux with
# D(T) at each point, gives the same permeation to 3e-8).
begin contact definition wall
  contact surface coating_back contains coating_back
  contact surface substrate_front contains substrate_front
  begin interaction
    side a coating_back
    side b substrate_front
  end
  begin enforcement thermal
    enforcement for energy = tied_temperature
  end
  begin enforcement hydrogen
    enforcement for species = tied multipliers = dual
    side b variable species to species
    partition coefficient = 0.1
  end
end
