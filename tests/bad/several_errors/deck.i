# Several independent mistakes: every one is reported in one run.
begin contact definition main
  contact surface top contains block_1
  contact surface top contains block_2
  output rule = verbos
  update search every two steps
  restrict contact to subdomain defined by radius 1 and point 0 0
  periodicity for top = rectangular offset = 1
  begin interaction a
    side a top
    normal tolerance 0
    enforcement = tide
  end
  begin enforcement tied
    enforcement for energy = tied_temperature
  end
  begin contact surface outer
    element = 1 2 x3
    subset lid with normal 0 0 0
    contact type = edge
  end contact surface
end contact definition mian
