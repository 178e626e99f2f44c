#!/usr/bin/env bash
# Writes the 40 3-D screening designs of the benchmarks into DIR: ten sharp and ten blunt bevels
# of 15°–60° as a design list (DIR/bevels.toml), ten cones and ten cylinders of 150–240 µm as STL
# files (run through the 3-D model, as a user's CAD exports are).
#   usage: bench/screen_designs.sh MNEEDLE DIR
set -euo pipefail
mneedle="$1"
dir="$2"
mkdir -p "$dir"
for i in $(seq 0 9); do
  angle=$((15 + 5 * i))
  printf '[[designs]]\nname = "sharp_%02d"\nplugin = "sharp_bevel"\nbevel_angle = "%d deg"\n\n' "$i" "$angle"
  printf '[[designs]]\nname = "blunt_%02d"\nplugin = "blunt_bevel"\nbevel_angle = "%d deg"\n\n' "$i" "$angle"
done > "$dir/bevels.toml"
for i in $(seq 0 9); do
  d=$((150 + 10 * i))
  "$mneedle" generate cone --set "diameter=${d}um" --unit um -o "$dir/cone_$i.stl" > /dev/null
  "$mneedle" generate cylinder --set "diameter=${d}um" --unit um -o "$dir/cylinder_$i.stl" > /dev/null
done
