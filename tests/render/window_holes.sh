#!/usr/bin/env bash
# Drives the hole finder of `liveset view` in a real X window (run under xvfb-run) with xdotool:
# a click on "Find holes", then (once the list is drawn) a click on its first row, then the N key
# (the next candidate); each step waits on the viewer's event log. The viewer is then closed.
# Usage: window_holes.sh LIVESET IMAGE MASK LOG   (exit: 0, or 90+ from the driver)
set -u
liveset=$1 image=$2 mask=$3 log=$4
rm -f "$log"
"$liveset" view "$image" --mask "$mask" --log-events "$log" --no-autosave --size 1280x1000 &
app=$!

. "$(dirname "$0")/window_driver.sh"
rect() {  # rect EVENT NAME: "x y w h" of a panel item from the last EVENT line
    grep "\"type\":\"$1\"" "$log" | tail -1 | grep -o "\"$2\":\[[0-9,]*\]" | head -1 | sed 's/.*\[//; s/\]//; s/,/ /g'
}
click_at() {  # click_at X Y W H: a left click in the middle of the rectangle
    xdotool mousemove --window "$window" $(($1 + $3 / 2)) $(($2 + $4 / 2))
    sleep 0.2
    xdotool click 1
}

wait_for '"type":"ready"' 30
window=$(xdotool search --sync --name '^liveset' | head -1)
click_at $(rect ready find_holes)
wait_for '"type":"holes"' 30
wait_for '"type":"hole_rows"' 30
sleep 1  # a few frames: the rows are logged again if the layout moves them
click_at $(rect hole_rows hole_1)
wait_for '"type":"select_hole"' 30
xdotool key n
wait_count '"type":"select_hole"' 1 30
kill "$app"
wait "$app"
exit 0
