#!/usr/bin/env bash
# Drives the slice panes of `liveset view` in a real X window (run under xvfb-run) with xdotool:
# a crosshair click, Ctrl+wheel zoom at the same pixel and a second click there, a middle-drag pan
# and a click at the dragged-to pixel, a right-drag zoom, a Shift+left drag (window/level), the
# label-opacity slider at 1 and at 0 with a window screenshot (F12) after each, typed cursor entry
# in 1-based voxels and in LPS millimetres, Ctrl+Q. Each step waits on the viewer's event log.
# Usage: window_slices.sh LIVESET IMAGE MASK LOG "X Y Z" (LPS mm to type)  (exit: the viewer's, or 90+)
set -u
liveset=$1 image=$2 mask=$3 log=$4 mm=$5
rm -f "$log"
"$liveset" view "$image" --mask "$mask" --log-events "$log" --no-autosave --size 1280x1000 &
app=$!

. "$(dirname "$0")/window_driver.sh"
rect() {  # rect NAME: "x y w h" of a pane or panel item from the ready line
    grep '"ready"' "$log" | grep -o "\"$1\":\[[0-9,]*\]" | head -1 | sed 's/.*\[//; s/\]//; s/,/ /g'
}
wait_count() {  # wait_count PATTERN N SECONDS: until N log lines match PATTERN
    for _ in $(seq 1 $(($3 * 10))); do
        [ "$(grep -c "$1" "$log" 2>/dev/null)" -ge "$2" ] && return 0
        kill -0 "$app" 2>/dev/null || { echo "viewer exited early" >&2; exit 91; }
        sleep 0.1
    done
    echo "timed out waiting for $2 x $1" >&2
    kill "$app" 2>/dev/null
    exit 90
}
screenshot() {  # F12 until the log has one more screenshot (a key right after a slider's release
    # can land in the frame where ImGui still holds the slider, and is then ImGui's)
    local before
    before=$(grep -c '"type":"screenshot"' "$log")
    for _ in 1 2 3 4 5 6; do
        xdotool key F12
        for _ in $(seq 1 30); do
            [ "$(grep -c '"type":"screenshot"' "$log" 2>/dev/null)" -gt "$before" ] && sleep 0.3 && return 0
            sleep 0.1
        done
    done
    echo "timed out waiting for a screenshot" >&2
    kill "$app" 2>/dev/null
    exit 90
}
drag() {  # drag BUTTON X0 Y0 DX DY: press, move in 6 steps, release
    xdotool mousemove --window "$window" "$2" "$3"
    sleep 0.2
    xdotool mousedown "$1"
    for k in 1 2 3 4 5 6; do
        xdotool mousemove --window "$window" $(($2 + $4 * k / 6)) $(($3 + $5 * k / 6))
        sleep 0.05
    done
    xdotool mouseup "$1"
}

wait_for '"type":"ready"' 60
window=$(xdotool search --sync --name '^liveset' | head -1)
read -r ax ay aw ah <<<"$(rect axial)"
px=$((ax + aw / 2 + 37)) py=$((ay + ah / 2 + 23))

# A crosshair click, Ctrl+wheel zoom (3 steps) at the same pixel, a click there again.
xdotool mousemove --window "$window" $px $py
sleep 0.3
xdotool click 1
wait_count '"type":"cursor"' 1 30
xdotool keydown ctrl click 4 click 4 click 4 keyup ctrl
wait_count '"gesture":"wheel"' 3 30
xdotool click 1
wait_count '"type":"cursor"' 2 30

# Middle drag (pan) by (30, 20), then a click at the pixel the content moved to.
drag 2 $px $py 30 20
wait_for '"gesture":"pan"' 30
xdotool mousemove --window "$window" $((px + 30)) $((py + 20))
sleep 0.2
xdotool click 1
wait_count '"type":"cursor"' 3 30

# Right drag upwards: zoom in about the press point.
drag 3 $((ax + aw / 2)) $((ay + ah / 2)) 0 -40
wait_for '"gesture":"zoom"' 30

# Shift + left drag: right widens the window, up raises the level.
xdotool keydown shift
drag 1 $((ax + 60)) $((ay + ah - 60)) 60 -30
xdotool keyup shift
wait_count '"type":"window"' 2 30

# The label-opacity slider at its right end (1) and left end (0), a window screenshot after each.
read -r ox oy ow oh <<<"$(rect label_opacity)"
xdotool mousemove --window "$window" $((ox + ow - 1)) $((oy + oh / 2))
sleep 0.2
xdotool click 1
wait_count '"type":"display"' 1 30
screenshot
cp screenshot.png opaque.png
xdotool mousemove --window "$window" $((ox + 1)) $((oy + oh / 2))
sleep 0.2
xdotool click 1
wait_count '"type":"display"' 2 30
screenshot
cp screenshot.png clear.png

# Typed cursor entry: 1-based voxels, then LPS millimetres.
read -r vx vy vw vh <<<"$(rect cursor_voxel)"
xdotool mousemove --window "$window" $((vx + vw / 2)) $((vy + vh / 2))
sleep 0.2
xdotool click 1
sleep 0.2
xdotool type --delay 30 "10 20 30"
xdotool key Return
wait_count '"how":"typed"' 1 30
read -r mx my mw mh <<<"$(rect cursor_mm)"
xdotool mousemove --window "$window" $((mx + mw / 2)) $((my + mh / 2))
sleep 0.2
xdotool click 1
sleep 0.2
xdotool type --delay 30 "$mm"
xdotool key Return
wait_count '"how":"typed"' 2 30

xdotool key ctrl+q
wait "$app"
