mod mesh_io;
