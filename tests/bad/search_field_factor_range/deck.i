# A negative field factor accepts no gap: every point would be dropped (heat 0).
begin contact definition main
  skin all blocks = on
  begin search options
    field factor = -3
  end
end
