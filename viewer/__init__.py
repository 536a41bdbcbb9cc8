"""The pyvista viewer of formgraph (imports pyvista lazily)."""
