#!/usr/bin/env bash
# Drives `liveset view` in a real X window (run under xvfb-run) with xdotool: a seed clicked outside
# the ROI is refused (the event log's error names the ROI), one inside is placed; µ is typed in raw
# units into the panel's field (a single click, no hidden gesture); Ctrl+Q then asks
# (unsaved work): Cancel keeps the viewer open, a second Ctrl+Q asks again and its Quit button quits.
# Usage: window_prompts.sh LIVESET IMAGE ROI LOG MU  (MU: a whole number; exit status: the viewer's, or 90+)
set -u
liveset=$1 image=$2 roi=$3 log=$4 mu=$5
rm -f "$log"
"$liveset" view "$image" --roi "$roi" --log-events "$log" --recovery-dir "$(dirname "$log")/recovery" &
app=$!

. "$(dirname "$0")/window_driver.sh"
rect() {  # rect NAME: "x y w h" from the ready line
    grep '"ready"' "$log" | grep -o "\"$1\":\[[0-9,]*\]" | head -1 | sed 's/.*\[//; s/\]//; s/,/ /g'
}
button() {  # button EVENT NAME: "x y w h" of a dialog's button from its last EVENT line
    grep "\"type\":\"$1\"" "$log" | grep "\"$2\":\[" | tail -1 | grep -o "\"$2\":\[[0-9,]*\]" | sed 's/.*\[//; s/\]//; s/,/ /g'
}
click_at() {
    xdotool mousemove --window "$window" "$1" "$2"
    sleep 0.3
    xdotool click 1
}

wait_for '"type":"ready"' 60
window=$(xdotool search --sync --name '^liveset' | head -1)
read -r ax ay aw ah <<<"$(rect axial)"
xdotool mousemove --window "$window" $((ax + aw / 2)) $((ay + ah / 2))
sleep 0.3
xdotool key 2  # the seed tool
wait_for '"action":"seed"' 30
click_at $((ax + aw / 2 - ah * 3 / 10)) $((ay + ah / 2 - ah * 3 / 10))  # inside the image, outside the ROI
wait_for 'outside the region of interest' 30
click_at $((ax + aw / 2)) $((ay + ah / 2))  # the centre: inside the ROI
wait_for '"type":"seed"' 30

# µ typed in raw units: one click in the field, select all, type, Enter.
read -r mx my mw mh <<<"$(rect mu_field)"
click_at $((mx + mw / 2)) $((my + mh / 2))
xdotool key ctrl+a
xdotool type --delay 50 "$mu"
xdotool key Return
wait_for "\"mu_raw\":$mu.0" 30
xdotool mousemove --window "$window" $((ax + aw / 2)) $((ay + ah / 2))
sleep 0.3

xdotool key ctrl+q
wait_for '"buttons".*"type":"quit_prompt"' 30
read -r qx qy qw qh <<<"$(button quit_prompt cancel)"
click_at $((qx + qw / 2)) $((qy + qh / 2))
wait_for '"answer":"cancel"' 30
sleep 0.5
kill -0 "$app" || exit 92  # still open
xdotool key ctrl+q
wait_count '"buttons".*"type":"quit_prompt"' 1 30
read -r qx qy qw qh <<<"$(button quit_prompt quit)"
click_at $((qx + qw / 2)) $((qy + qh / 2))
wait "$app"
