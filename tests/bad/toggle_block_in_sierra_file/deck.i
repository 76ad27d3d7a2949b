Begin Sierra job
  Begin Finite Element Model mesh1
    Database Name = mesh.exo
  End
  Begin Toggle Block tog
    Add Interval int_1
  End
  Begin Procedure p
    Begin Aria Region r
      Begin Contact Definition cd
        Contact Surface surface_1
        Begin Enforcement gap
          Enforcement For Energy Gap_Conductance H = 10
          Use Toggle Block tog block_1
        End
      End
    End
  End
End
