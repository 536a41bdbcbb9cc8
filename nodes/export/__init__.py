"""The ``export.*`` nodes: files written atomically inside the output folder.

``mesh`` (STL, OBJ, PLY), ``drawing`` (SVG, PDF, DXF) and ``exchange`` (3MF, glTF, STEP, Rhino).
"""
