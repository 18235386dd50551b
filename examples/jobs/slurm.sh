#!/bin/bash
# Renders examples/animation/orbit.sdf (180 frames) as a Slurm job array of 10 tasks: task I
# renders the frames k with k mod 10 = I. Submit from the repository's root with
#   sbatch examples/jobs/slurm.sh
# A task that is killed (preempted, out of time) leaves only whole frames behind; requeue or
# submit again and each task renders only the frames still missing.
#SBATCH --job-name=sdfc-orbit
#SBATCH --array=0-9
#SBATCH --gpus=1
#SBATCH --cpus-per-task=4
#SBATCH --time=00:30:00
#SBATCH --output=logs/orbit_%A_%a.log
set -euo pipefail

mkdir -p logs frames
sdfc render examples/animation/orbit.sdf \
    --size 1920x1080 \
    --frames 0..180 \
    --shard "$SLURM_ARRAY_TASK_ID/$SLURM_ARRAY_TASK_COUNT" \
    -o frames/orbit_####.png
