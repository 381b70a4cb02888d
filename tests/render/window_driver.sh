# Shared by the real-window test drivers (sourced): waits on the viewer's event log.
# Needs $log (the --log-events file) and $app (the viewer's pid).

wait_for() {  # wait_for PATTERN SECONDS: until the log has a line matching PATTERN
    for _ in $(seq 1 $(($2 * 10))); do
        grep -q "$1" "$log" 2>/dev/null && return 0
        kill -0 "$app" 2>/dev/null || { echo "viewer exited early" >&2; exit 91; }
        sleep 0.1
    done
    echo "timed out waiting for $1" >&2
    kill "$app" 2>/dev/null
    exit 90
}

wait_count() {  # wait_count PATTERN N SECONDS: until more than N lines of the log match PATTERN
    for _ in $(seq 1 $(($3 * 10))); do
        [ "$(grep -c "$1" "$log" 2>/dev/null)" -gt "$2" ] && return 0
        kill -0 "$app" 2>/dev/null || { echo "viewer exited early" >&2; exit 91; }
        sleep 0.1
    done
    echo "timed out waiting for $1 (more than $2)" >&2
    kill "$app" 2>/dev/null
    exit 90
}
