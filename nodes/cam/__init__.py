"""The ``cam.*`` nodes: CNC tool-centre paths, ``profile`` (along outlines) and ``pocket``
(clearing regions), at step-down depths (:mod:`formgraph.kernels.cam`); ``export.gcode``
writes them for the machine."""
