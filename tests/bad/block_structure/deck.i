begin contact defintion main
  contact surface top contains block_1
end
begin interaction loose
  side a top
end
begin contact definition main
  begin interaction defaults extra
    general contact = of
  end
  begin enforcement e
    begin search options
    end
  end
end
end
