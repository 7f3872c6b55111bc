//! Gmsh MSH 2.2 and 4.1 readers (ASCII and binary) and the MSH 4.1 ASCII writer.
