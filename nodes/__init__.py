"""Node families of formgraph: one module per family, registered on import."""
