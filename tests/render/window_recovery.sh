#!/usr/bin/env bash
# Drives `liveset view` in a real X window (run under xvfb-run): the image has a recovery file, so
# the viewer opens with its "Restore unsaved work?" dialog; a real click on "Restore" (xdotool)
# restores it and the window redraws without the dialog with no further input; Ctrl+Q asks (the
# restored work is unsaved), a second Ctrl+Q quits. Each step waits until the viewer's event log shows the reaction.
# Usage: window_recovery.sh LIVESET IMAGE RECOVERY_DIR LOG  (exit status: the viewer's, or 90+)
set -u
liveset=$1 image=$2 recovery=$3 log=$4
rm -f "$log"
"$liveset" view "$image" --recovery-dir "$recovery" --log-events "$log" &
app=$!

. "$(dirname "$0")/window_driver.sh"

wait_for '"type":"recovery_offer"' 60
window=$(xdotool search --sync --name '^liveset' | head -1)
read -r bx by bw bh <<<"$(grep '"recovery_offer"' "$log" | grep -o '"restore":\[[0-9,]*\]' | head -1 | sed 's/.*\[//; s/\]//; s/,/ /g')"
xdotool mousemove --window "$window" $((bx + bw / 2)) $((by + bh / 2))
sleep 0.3
xdotool click 1
wait_for '"type":"restore"' 30
# The window redraws without the dialog by itself: no pointer motion or key after the click.
wait_for '"type":"recovery_closed"' 10
xdotool key ctrl+q
wait_for '"buttons".*"type":"quit_prompt"' 30  # the restored work is unsaved: asked first
xdotool key ctrl+q
wait "$app"
