#!/bin/sh
# The least material for a printable lamp shade that still lets light out and is stiff
# enough: vary the wall, the windows' size and their height; minimise the shade's volume
# (its material) subject to a light opening of at least 1.2 (eight windows of radius
# >= 0.22), one printable piece, and a ring-stiffness proxy (wall^3, weakened by the share
# of the ring the windows take).
set -e
formgraph optimize graphs/lamp_shade.yaml \
  --vary wall=0.02:0.3 window=0.05:0.5 height=0.6:2.2 \
  --minimize size.volume \
  --constraint "8 * pi * window**2 >= 1.2" \
  --constraint "size.parts <= 1" \
  --constraint "wall**3 * (1 - window / 0.6) >= 5e-5" \
  --budget 60 --seed 1 --render lamp_shade --export --out out/lamp_optimum "$@"
