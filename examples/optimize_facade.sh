#!/bin/sh
# Daylight against material on a facade (graphs/facade_daylight.yaml): maximise the glazed
# area, minimise the frames' volume, with frames deep enough to shade their window
# (depth >= 0.3 h) and windows that fit across the front. NSGA-II, two objectives: the
# Pareto front in out/facade_front/pareto.csv and progress.png, drawn in front.png.
set -e
formgraph optimize graphs/facade_daylight.yaml \
  --vary columns=2:10 floors=1:4 w=0.4:1.6 h=0.5:2.4 depth=0.05:0.8 \
  --maximize daylight.volume --minimize material.volume \
  --constraint "depth - 0.3 * h >= 0" --constraint "w * columns <= 10" \
  --method nsga2 --budget 200 --batch 20 --seed 1 --render facade --out out/facade_front "$@"
