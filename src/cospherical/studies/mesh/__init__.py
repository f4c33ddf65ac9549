"""Meshing a 1-irregular octree from the pattern tables: the tree, the assembly, and the exact checks."""
