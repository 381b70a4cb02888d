#!/usr/bin/env bash
# Drives `liveset view` in a real X window (run under xvfb-run) with real input events from
# xdotool: rotate the 3D view by dragging, pick the surface with the target tool, run and stop
# the swarm, press the panel's "Reset view" button, quit with Ctrl+Q twice (the first asks: the
# swarm's unsaved edits go to a recovery file next to the log). Each step waits until the viewer's event log shows the
# reaction, so a slow software renderer only makes it slower.
# Usage: window_smoke.sh LIVESET IMAGE MASK LOG  (exit status: the viewer's, or 90+ on a timeout)
set -u
liveset=$1 image=$2 mask=$3 log=$4
rm -f "$log"
"$liveset" view "$image" --mask "$mask" --log-events "$log" --recovery-dir "$(dirname "$log")/recovery" &
app=$!

. "$(dirname "$0")/window_driver.sh"
rect() {  # rect NAME: "x y w h" of a pane or button from the ready line
    grep '"ready"' "$log" | grep -o "\"$1\":\[[0-9,]*\]" | head -1 | sed 's/.*\[//; s/\]//; s/,/ /g'
}

wait_for '"type":"ready"' 60
window=$(xdotool search --sync --name '^liveset' | head -1)
read -r px py pw ph <<<"$(rect 3d)"
cx=$((px + pw / 2)) cy=$((py + ph / 2))

# Rotate: a left drag across the 3D pane.
xdotool mousemove --window "$window" $cx $cy
sleep 0.3
xdotool mousedown 1
for dx in 10 20 30 40 50 60; do
    xdotool mousemove --window "$window" $((cx + dx)) $((cy + dx / 3))
    sleep 0.05
done
xdotool mouseup 1
wait_for '"gesture":"rotate"' 30

# Target tool, then a click on the surface in the middle of the 3D pane.
xdotool key 3
wait_for '"action":"target"' 30
xdotool mousemove --window "$window" $cx $cy
sleep 0.3
xdotool click 1
wait_for '"type":"target"' 30

# Run the swarm for a moment, then stop it (key T twice).
xdotool key t
wait_for '"running":true' 30
sleep 1
xdotool key t
wait_for '"running":false' 30

# The panel's "Reset view" button.
read -r bx by bw bh <<<"$(rect reset_view)"
xdotool mousemove --window "$window" $((bx + bw / 2)) $((by + bh / 2))
sleep 0.3
xdotool click 1
wait_for '"name":"reset_view"' 30

# Ctrl+Q with the swarm's edits unsaved: the viewer asks first; a second Ctrl+Q means it.
xdotool key ctrl+q
wait_for '"buttons".*"type":"quit_prompt"' 30
xdotool key ctrl+q
wait "$app"
