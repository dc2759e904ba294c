"""Parametric gate-frame geometry, gmsh meshing, named regions and sensors."""
