#!/bin/bash
# Same study with the fatigue driver averaged over R = 3 mm
for h in 4 3 2 1.5; do
  /usr/bin/time -v ./pneufem_nl simulate /work/main/scenes/examples/paper_story.toml --out nl_h$h \
    --set geometry.chambers=3 --set materials.silicone.fatigue.tau_s=80.0 --set load.trials=2 \
    --set materials.silicone.fatigue.nonlocal_radius_mm=3.0 \
    --set mesh.h_mm=$h --set output.vtu=\"none\" --threads 1 > nl_h$h.log 2>&1
  echo "nl h=$h done $(date +%T)" >> progress.log
done
