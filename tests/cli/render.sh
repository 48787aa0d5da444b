#!/usr/bin/env bash
# End-to-end: driftless render from a log (MP4 decoded with ffprobe), the PNG fallback without
# ffmpeg, a clear error without OpenGL, and a rendered scenario.
# usage: render.sh <path-to-driftless> <source-dir>
set -euo pipefail
bin=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }

# a small box model (box body on slides + ball, hinge1/hinge2 platforms, gyro sites, cameras)
cat > "$work/box.xml" <<'XML'
<mujoco model="cli_box">
  <compiler angle="degree"/>
  <worldbody>
    <light pos="0 0 3" dir="0 0 -1" directional="true"/>
    <geom type="plane" size="5 5 0.1" pos="0 0 -0.2" rgba="0.8 0.8 0.75 1"/>
    <camera name="cam_fixed" pos="0.05 -0.28 0.17" xyaxes="1 0 0 0 0.5 0.87"/>
    <body name="box">
      <joint name="drive_x" type="slide" axis="1 0 0"/>
      <joint name="drive_y" type="slide" axis="0 1 0"/>
      <joint name="drive_z" type="slide" axis="0 0 1"/>
      <joint name="drive_rot" type="ball"/>
      <geom type="box" size="0.1 0.07 0.045" rgba="0.55 0.75 0.95 0.2" contype="0" conaffinity="0"/>
      <body name="platform1" pos="-0.045 0 0">
        <joint name="hinge1" type="hinge" axis="0 0 1"/>
        <geom type="box" size="0.03 0.03 0.002" rgba="0.1 0.6 0.25 1" contype="0" conaffinity="0"/>
        <site name="imu1" size="0.003"/>
      </body>
      <body name="platform2" pos="0.045 0 0">
        <joint name="hinge2" type="hinge" axis="1 0 0"/>
        <geom type="box" size="0.002 0.03 0.03" rgba="0.1 0.35 0.75 1" contype="0" conaffinity="0"/>
        <site name="imu2" size="0.003"/>
      </body>
    </body>
  </worldbody>
  <sensor><gyro site="imu1"/><gyro site="imu2"/></sensor>
</mujoco>
XML

# 2 s at 100 Hz: platform 1 flips from +90 to -90 during 0.5..1.0 s (empty while moving)
{
  echo "# format: driftless-log 1"
  echo "# complete: true"
  echo "# sample_rate_hz: 100"
  echo "t,gyro1_x,gyro1_y,gyro1_z,gyro2_x,gyro2_y,gyro2_z,plat1_deg,plat2_deg,ref_qw,ref_qx,ref_qy,ref_qz"
  awk 'BEGIN { for (i = 0; i < 200; i++) { t = i / 100; p = (t < 0.5) ? "90" : (t < 1.0 ? "" : "-90");
               printf "%.6f,0.1,0.2,0.3,-0.1,0.05,0.2,%s,90,1,0,0,0\n", t, p } }'
} > "$work/run.csv"

# 1. MP4 through ffmpeg: 2 s at 10 frames/s = 20 frames of 160x120
"$bin" render --log "$work/run.csv" --model "$work/box.xml" --out "$work/v.mp4" \
  --width 160 --height 120 --fps 10 --camera cam_fixed > "$work/out.txt"
probe=$(ffprobe -v error -count_frames -select_streams v:0 \
  -show_entries stream=codec_name,nb_read_frames,width,height,r_frame_rate -of default=nw=1 "$work/v.mp4")
grep -qx "codec_name=h264" <<< "$probe" || fail "not H.264: $probe"
grep -qx "nb_read_frames=20" <<< "$probe" || fail "frame count: $probe"
grep -qx "width=160" <<< "$probe" || fail "width: $probe"
grep -qx "height=120" <<< "$probe" || fail "height: $probe"
grep -qx "r_frame_rate=10/1" <<< "$probe" || fail "fps: $probe"

# 2. no ffmpeg: numbered PNG frames and a message that says so
DRIFTLESS_FFMPEG=/nonexistent/ffmpeg "$bin" render --log "$work/run.csv" --model "$work/box.xml" \
  --out "$work/p.mp4" --width 160 --height 120 --fps 10 --to 1 2> "$work/err.txt" > /dev/null
grep -q "ffmpeg program was not found" "$work/err.txt" || fail "no fallback message: $(cat "$work/err.txt")"
[ ! -e "$work/p.mp4" ] || fail "an MP4 appeared without ffmpeg"
[ "$(ls "$work/p_frames" | grep -c '^frame_[0-9]\{6\}\.png$')" = 10 ] || fail "expected 10 PNG frames"

# 3. no OpenGL context: exit status 1 (not a crash) and one clear line
set +e
DRIFTLESS_RENDER_NO_GL=1 "$bin" render --log "$work/run.csv" --model "$work/box.xml" \
  --out "$work/n.mp4" 2> "$work/err.txt" > /dev/null
rc=$?
set -e
[ $rc -eq 1 ] || fail "no-GL exit status $rc (want 1)"
grep -q "^driftless render: error: no OpenGL context" "$work/err.txt" || fail "no-GL message: $(cat "$work/err.txt")"

# 4. an unknown camera names the model's cameras
set +e
"$bin" render --log "$work/run.csv" --model "$work/box.xml" --out "$work/c.mp4" --camera nope \
  2> "$work/err.txt" > /dev/null
rc=$?
set -e
[ $rc -eq 1 ] || fail "bad camera exit status $rc"
grep -q "cam_fixed" "$work/err.txt" || fail "bad camera message: $(cat "$work/err.txt")"

# 5. a simulated scenario (built-in 'static') in the shipped model: 1 s at 10 frames/s
"$bin" render --scenario static --out "$work/s.mp4" --width 160 --height 120 --fps 10 --to 1 \
  > /dev/null
n=$(ffprobe -v error -count_frames -select_streams v:0 -show_entries stream=nb_read_frames \
    -of default=nw=1:nk=1 "$work/s.mp4")
[ "$n" = 10 ] || fail "scenario render: $n frames (want 10)"
# 1 s cannot lock the overlaid filter: the sidecar says so and stderr names the fix
grep -q '"locked_from_t_s": null' "$work/s.json" || fail "scenario render: lock not in video.json: $(cat "$work/s.json")"
"$bin" render --scenario static --out "$work/s2.mp4" --width 160 --height 120 --fps 10 --to 1 --selfcal \
  > /dev/null 2> "$work/s2.err"
grep -q "never locked on" "$work/s2.err" || fail "render: an unlocked overlay filter is not said: $(cat "$work/s2.err")"
grep -q '"self_calibration": true' "$work/s2.json" || fail "render --selfcal not in video.json"
if "$bin" render --scenario static --out "$work/s3.mp4" --selfcal --no-estimate > /dev/null 2>&1; then
  fail "render: --selfcal with --no-estimate accepted"
fi

# 6. only `render` maps the GL stack: the program does not need libOSMesa (and its libLLVM) at
#    start-up; renders/gl_api.cpp loads it when a context is made (step 5 proved that works)
if command -v readelf > /dev/null; then
  if readelf -d "$bin" | grep -E "NEEDED.*(libOSMesa|libLLVM|libGL)" > "$work/needed.txt"; then
    fail "driftless links the GL stack at start-up: $(cat "$work/needed.txt")"
  fi
fi
echo "render: ok"
