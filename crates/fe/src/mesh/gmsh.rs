//! Gmsh `.msh` 4.1 meshes, ASCII and binary.
