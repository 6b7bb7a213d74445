#!/bin/bash
# 3-chamber story (CI test constants tau = 80 s), two trials, mesh convergence of the fatigue drift
for h in 6 4 3 2 1.5; do
  /usr/bin/time -v ./pneufem_conv simulate /work/main/scenes/examples/paper_story.toml --out h$h \
    --set geometry.chambers=3 --set materials.silicone.fatigue.tau_s=80.0 --set load.trials=2 \
    --set mesh.h_mm=$h --set output.vtu=\"none\" --threads 1 > h$h.log 2>&1
  echo "h=$h done $(date +%T)" >> progress.log
done
