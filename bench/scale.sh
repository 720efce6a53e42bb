#!/usr/bin/env bash
# Scaling of the long set-up steps with their input size (issue "Nothing silent, round
# two", class 7): route compilation, the kinematic envelope check and gnss-ins-sim command
# lists must be linear. For each input it runs the same command at size n and 10·n and
# prints the CPU time (user + system) and peak memory of both, and their ratio; it fails
# when 10× the input costs more than 12× the time.
#
#   bench/scale.sh                 # builds target/release/sdins, default sizes
#   SDINS=/path/to/sdins bench/scale.sh       # another binary (e.g. an older build)
#   ROUTE_N=100 CMD_N=10000 bench/scale.sh    # the smaller sizes (the larger are 10×)
#
# The inputs:
#   route     ROUTE_N waypoints 4 km apart on 51 km circles (4.5° fly-by turns, 100 m/s,
#             1 Hz IMU): `sdins truth` compiles the route, checks the envelope and writes
#             the truth (linear in the duration by construction)
#   commands  CMD_N gnss-ins-sim commands of 1 s (type 1, small rates), imported at 1 Hz
#             (`sdins scenarios import`: parse, compile, TOML), then `sdins truth` on the
#             TOML (parse, compile, envelope check, truth)
# Wall time is printed too, but on a shared machine CPU time is the figure to compare.
#
# Measured (2 shared cores, CPU s for n → 10·n):
#                          before (main f3011cd)            after
#   route, 100 → 1000      0.76 → 25.48 s (33.5×)           0.94 → 9.97 s (10.6×)
#   commands import        2 000 → 20 000: 0.04 → 1.27 s (31.8×)   10 000 → 100 000: 0.18 → 1.92 s (10.7×)
#   commands sdins truth   2 000 → 20 000: 0.05 → 2.19 s (43.8×)   10 000 → 100 000: 0.19 → 1.97 s (10.4×)
# (the quadratic part was Trajectory::segment_at, a linear scan at every kinematics
# evaluation of the envelope check and the truth generator)
set -euo pipefail
cd "$(dirname "$0")/.."
ROUTE_N=${ROUTE_N:-100}
CMD_N=${CMD_N:-10000}
MAX_RATIO=${MAX_RATIO:-12}
if [[ -z "${SDINS:-}" ]]; then
    cargo build --release -q -p sdins-cli
    SDINS=target/release/sdins
fi
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

route_toml() { # n
    python3 - "$1" <<'EOF'
import math, sys
n = int(sys.argv[1])
a, e2 = 6378137.0, 6.69437999014e-3
lat0 = math.radians(45.0)
w = 1 - e2 * math.sin(lat0) ** 2
r_m, r_n = a * (1 - e2) / w ** 1.5, a / math.sqrt(w)
R, per = 51000.0, 80
print("name = \"scale-route\"\n[imu]\nrate_hz = 1.0\n[route]\nlegs = \"great_circle\"")
for k in range(n):
    th = 2 * math.pi * k / per
    lat = 45.0 + math.degrees(R * math.cos(th) / r_m)
    lon = 10.0 + math.degrees(R * math.sin(th) / (r_n * math.cos(lat0)))
    print(f"[[waypoint]]\nlat_deg = {lat:.9f}\nlon_deg = {lon:.9f}\nspeed_mps = 100.0")
EOF
}

commands_csv() { # n
    python3 - "$1" <<'EOF'
import sys
n = int(sys.argv[1])
print("ini lat (deg),ini lon (deg),ini alt (m),ini vx_body (m/s),ini vy_body (m/s),ini vz_body (m/s),ini yaw (deg),ini pitch (deg),ini roll (deg)")
print("32,120,0,10,0,0,0,0,0")
print("command type,yaw (deg),pitch (deg),roll (deg),vx_body (m/s),vy_body (m/s),vz_body (m/s),command duration (s),GPS visibility")
for k in range(n):
    r = 0.5 if k % 4 < 2 else -0.5
    print(f"1,{r},0,0,0,0,0,1,{1 if k % 100 else 0}")
EOF
}

# run LABEL CMD...: prints "cpu_s wall_s maxrss_MB" for the command
measure() {
    /usr/bin/time -o "$work/time" -f "%U %S %e %M" "$@" >/dev/null 2>"$work/err" || {
        echo "failed: $*" >&2
        cat "$work/err" >&2
        exit 1
    }
    read -r u s e m <"$work/time"
    awk -v u="$u" -v s="$s" -v e="$e" -v m="$m" 'BEGIN { printf "%.2f %.2f %.0f\n", u + s, e, m / 1024 }'
}

status=0
report() { # name n1 fig1 n2 fig2
    local name=$1 n1=$2 n2=$4
    read -r c1 w1 m1 <<<"$3"
    read -r c2 w2 m2 <<<"$5"
    local ratio
    ratio=$(awk -v a="$c1" -v b="$c2" 'BEGIN { printf "%.2f", (a > 0.005 ? b / a : 0) }')
    printf "%-24s n = %-8s cpu %8.2f s  wall %8.2f s  rss %6s MB\n" "$name" "$n1" "$c1" "$w1" "$m1"
    printf "%-24s n = %-8s cpu %8.2f s  wall %8.2f s  rss %6s MB\n" "" "$n2" "$c2" "$w2" "$m2"
    if awk -v r="$ratio" -v m="$MAX_RATIO" 'BEGIN { exit !(r <= m) }'; then
        printf "%-24s 10x input: %sx cpu time (limit %sx): linear\n" "" "$ratio" "$MAX_RATIO"
    else
        printf "%-24s 10x input: %sx cpu time (limit %sx): SUPERLINEAR\n" "" "$ratio" "$MAX_RATIO"
        status=1
    fi
}

echo "sdins: $SDINS"
# routes
for n in "$ROUTE_N" $((ROUTE_N * 10)); do
    route_toml "$n" >"$work/route-$n.toml"
done
r1=$(measure "$SDINS" truth "$work/route-$ROUTE_N.toml" --out "$work/o1" --every 1000000 --quiet)
r2=$(measure "$SDINS" truth "$work/route-$((ROUTE_N * 10)).toml" --out "$work/o2" --every 1000000 --quiet)
report "route (sdins truth)" "$ROUTE_N" "$r1" "$((ROUTE_N * 10))" "$r2"

# gnss-ins-sim command lists
for n in "$CMD_N" $((CMD_N * 10)); do
    commands_csv "$n" >"$work/cmd-$n.csv"
done
i1=$(measure "$SDINS" scenarios import "$work/cmd-$CMD_N.csv" --rate-hz 1)
i2=$(measure "$SDINS" scenarios import "$work/cmd-$((CMD_N * 10)).csv" --rate-hz 1)
report "commands (import)" "$CMD_N" "$i1" "$((CMD_N * 10))" "$i2"
for n in "$CMD_N" $((CMD_N * 10)); do
    "$SDINS" scenarios import "$work/cmd-$n.csv" --rate-hz 1 >"$work/cmd-$n.toml"
done
t1=$(measure "$SDINS" truth "$work/cmd-$CMD_N.toml" --out "$work/o3" --every 1000000 --quiet)
t2=$(measure "$SDINS" truth "$work/cmd-$((CMD_N * 10)).toml" --out "$work/o4" --every 1000000 --quiet)
report "commands (sdins truth)" "$CMD_N" "$t1" "$((CMD_N * 10))" "$t2"
exit $status
