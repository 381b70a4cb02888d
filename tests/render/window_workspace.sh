#!/usr/bin/env bash
# Drives `liveset view` in a real X window (run under xvfb-run) with xdotool: a workspace saved,
# reopened and continued. Phase 1 opens IMAGE with a seed file, takes 5 segmentation steps (key S),
# turns the 3D view (a drag), saves the workspace with Ctrl+S (the panel's default workspace.json in
# the current folder) and quits (Ctrl+Q: nothing unsaved, no prompt). Phase 2 reopens it with
# --workspace, takes 3 more steps, saves it again and quits. Each step waits on the event log.
# Usage: window_workspace.sh LIVESET IMAGE SEEDS LOG PHASE  (exit status: the viewer's, or 90+)
set -u
liveset=$1 image=$2 seeds=$3 log=$4 phase=$5
rm -f "$log"
if [ "$phase" = 1 ]; then
    "$liveset" view "$image" --seeds "$seeds" --log-events "$log" --recovery-dir "$(dirname "$log")/recovery" &
    steps=5
else
    "$liveset" view --workspace workspace.json --log-events "$log" --recovery-dir "$(dirname "$log")/recovery" &
    steps=3
fi
app=$!

. "$(dirname "$0")/window_driver.sh"
rect() {  # rect NAME: "x y w h" of a pane or button from the ready line
    grep '"ready"' "$log" | grep -o "\"$1\":\[[0-9,]*\]" | head -1 | sed 's/.*\[//; s/\]//; s/,/ /g'
}

wait_for '"type":"ready"' 60
window=$(xdotool search --sync --name '^liveset' | head -1)
read -r px py pw ph <<<"$(rect 3d)"
cx=$((px + pw / 2)) cy=$((py + ph / 2))
xdotool mousemove --window "$window" $cx $cy  # the pointer over the 3D pane: keys go to the viewer
sleep 0.3
for i in $(seq 1 $steps); do
    xdotool key s
    wait_count '"action":"segmentation step"' $((i - 1)) 30
done
if [ "$phase" = 1 ]; then  # turn the view: the workspace keeps the camera
    xdotool mousedown 1
    for dx in 10 20 30 40; do
        xdotool mousemove --window "$window" $((cx + dx)) $((cy + dx / 2))
        sleep 0.05
    done
    xdotool mouseup 1
    wait_for '"gesture":"rotate"' 30
fi
xdotool key ctrl+s  # save the workspace (the panel's path)
wait_for '"what":"workspace"' 30
xdotool key ctrl+q
wait "$app"
