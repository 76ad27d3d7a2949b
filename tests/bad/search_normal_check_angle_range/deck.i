# An angle between two normals lies in [0, 180]: 720 would be cos 720° = 1 and pair
# only exactly opposed faces, silently dropping the rest.
begin contact definition main
  skin all blocks = on
  begin interaction defaults
    general contact = on
  end
  begin search options
    normal check angle = 720
  end
end
