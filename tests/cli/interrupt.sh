#!/usr/bin/env bash
# SIGINT / SIGTERM of each long command: exit 130 / 143, the outputs finished as incomplete (a log
# says complete: false, summary.json "complete": false and where it stopped), no partial file left.
set -uo pipefail
bin=$1; src=$2
t=$(mktemp -d)
pids=()
cleanup() { for p in "${pids[@]}"; do kill -9 "$p" 2>/dev/null; done; rm -rf "$t"; }
trap cleanup EXIT
fail() { echo "FAIL: $*"; exit 1; }

# wait_for FILE: until it exists (the command got going), at most 60 s
wait_for() {
  for _ in $(seq 600); do [[ -e $1 ]] && return 0; sleep 0.1; done
  fail "timed out waiting for $1"
}
# stop PID SIGNAL WANT NAME: send the signal, wait, check the exit status
stop() {
  kill -"$2" "$1"
  wait "$1"
  local rc=$?
  [[ $rc -eq $3 ]] || { cat "$t/$4.err" 2>/dev/null; fail "$4: exit status $rc after SIG$2, want $3"; }
}
no_partials() { [[ -z $(find "$1" -name '*.partial-*' 2>/dev/null) ]] || { find "$1"; fail "$2: a partial file was left"; }; }

# simulate: SIGINT -> 130, SIGTERM -> 143; the log stays valid and says complete: false
for sig in INT TERM; do
  want=$([[ $sig == INT ]] && echo 130 || echo 143)
  "$bin" simulate --scenario vehicle --duration 100000 --out "$t/sim_$sig" > /dev/null 2> "$t/sim_$sig.err" &
  pid=$!; pids+=("$pid")
  wait_for "$t/sim_$sig/log.csv"; sleep 0.5
  stop "$pid" "$sig" "$want" "sim_$sig"
  grep -q "^# complete: false" "$t/sim_$sig/log.csv" || fail "simulate $sig: the log does not say complete: false"
  grep -q "^# incomplete: stopped" "$t/sim_$sig/log.csv" || fail "simulate $sig: no '# incomplete:' trailer"
  "$bin" check --log "$t/sim_$sig/log.csv" > /dev/null || fail "simulate $sig: check refuses the stopped log"
done

# estimate on an endless stream (a FIFO fed by awk): SIGTERM -> 143, summary.json says where it stopped
mkfifo "$t/stream.csv"
awk 'BEGIN { print "# format: driftless-log 1"; print "# complete: false"; print "# sample_rate_hz: 100";
             print "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg";
             for (i = 0; ; i++) printf "%.2f,0.5,-0.3,0.8,-0.6,0.4,0.2,90,90\n", i * 0.01 }' > "$t/stream.csv" 2>/dev/null &
pids+=("$!")
"$bin" estimate --log "$t/stream.csv" --out "$t/est" --corrected > /dev/null 2> "$t/est.err" &
pid=$!; pids+=("$pid")
wait_for "$t/est/config_used.txt"; sleep 1
stop "$pid" TERM 143 est
grep -q '"complete": false' "$t/est/summary.json" || fail "estimate: summary.json lacks \"complete\": false"
grep -q '"stopped_at_t_s": [0-9]' "$t/est/summary.json" || fail "estimate: summary.json lacks stopped_at_t_s"
[[ $(wc -l < "$t/est/corrected.csv") -gt 1000 ]] || fail "estimate: corrected.csv lacks the rows before the stop"
no_partials "$t/est" estimate

# hil on the emulated bus in real time: SIGINT -> 130, the log ends cleanly
"$bin" hil --source emu-i2c --realtime --duration 600 --out "$t/hil" > /dev/null 2> "$t/hil.err" &
pid=$!; pids+=("$pid")
wait_for "$t/hil/log.csv"; sleep 1
stop "$pid" INT 130 hil
"$bin" check --log "$t/hil/log.csv" > /dev/null || fail "hil: check refuses the log of the stopped session"

# calibrate on the shipped rig with 10x longer segments (the shipped rig can finish within the 2 s
# before the signal on an idle machine): SIGINT -> 130, no calibration file that would look whole
mkdir -p "$t/cal"
sed 's/^\(  segment_s:\) *60 /\1 600 /' "$src/models/scenarios/calibration.yaml" > "$t/cal/rig.yaml"
grep -q '^  segment_s: 600 ' "$t/cal/rig.yaml" || fail "calibrate: could not lengthen the rig's segments"
"$bin" calibrate --scenario "$t/cal/rig.yaml" --out "$t/cal/calib.yaml" > /dev/null 2> "$t/cal.err" &
pid=$!; pids+=("$pid")
sleep 2
stop "$pid" INT 130 cal
[[ ! -e $t/cal/calib.yaml ]] || fail "calibrate: a calib.yaml after the stop"

# render a long scenario: SIGTERM -> 143
"$bin" render --scenario static --out "$t/r/video.mp4" --width 160 --height 120 --fps 10 > /dev/null 2> "$t/r.err" &
pid=$!; pids+=("$pid")
sleep 2
stop "$pid" TERM 143 r
no_partials "$t/r" render
# sweep of long runs: SIGINT -> 130 within seconds (the run in progress stops too), the table is
# written with the unfinished runs marked failed
cat > "$t/sweep.yaml" <<YAML
name: interrupt_test
runner: fast
scenario: static
duration_s: 200000
monte_carlo: 2
seed: 3
grid:
  flip_angle_deg: {set: flip_schedule.flip_angle_deg, values: [90]}
YAML
"$bin" sweep --config "$t/sweep.yaml" --out "$t/sw" --jobs 1 --no-plots > /dev/null 2> "$t/sw.err" &
pid=$!; pids+=("$pid")
sleep 2
started=$SECONDS
stop "$pid" INT 130 sw
(( SECONDS - started <= 5 )) || fail "sweep: took $(( SECONDS - started )) s to stop"
[[ $(grep -c ",failed: stopped" "$t/sw/runs.csv") -eq 2 ]] || { cat "$t/sw/runs.csv"; fail "sweep: runs.csv does not mark the stopped runs"; }
no_partials "$t/sw" sweep

# demo: SIGTERM while it simulates -> 143, the log says complete: false
"$bin" demo --out "$t/demo" --duration 100000 --no-video > /dev/null 2> "$t/demo.err" &
pid=$!; pids+=("$pid")
wait_for "$t/demo/sim/log.csv"; sleep 0.5
stop "$pid" TERM 143 demo
grep -q "^# complete: false" "$t/demo/sim/log.csv" || fail "demo: the stopped simulation's log does not say complete: false"
no_partials "$t/demo" demo
echo "interrupt: ok"
