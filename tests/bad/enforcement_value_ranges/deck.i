# A contact pressure is compressive: a negative one is tension (no contact), and a
# pressure-dependent conductance would take a power of it.
begin contact definition main
  contact surface top contains block_1
  contact surface bottom contains block_2
  begin enforcement warm
    enforcement for energy = gap_conductance
    gap conductance coefficient = constant h = 500
    contact surface pressure = constant value = -2e6
  end
end
