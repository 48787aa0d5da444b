#!/usr/bin/env bash
# The look test: what a reviewer sees. Runs the demo on a short run, opens report.html and the
# figures in headless Chromium (Debian 'chromium', installed by scripts/setup.sh) and checks that
# each screenshot is not blank, that no element overflows the page and that every image loads;
# then renders a few seconds around a flip and checks, on the decoded frames, that the box fills
# most of the frame height, that the flipping platform is shown large, and that the pixels of the
# view change across the flip and only then.
# usage: look.sh <path-to-driftless> <source-dir>
set -euo pipefail
bin=$1
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
fail() { echo "FAIL: $*" >&2; exit 1; }
command -v chromium >/dev/null || fail "chromium is not installed (scripts/setup.sh installs it: Debian package 'chromium')"
command -v ffmpeg >/dev/null || fail "ffmpeg is not installed (scripts/setup.sh installs it)"

# ---- pixels: decoded with ffmpeg, read by awk as "r g b" lines ----
rgb() { ffmpeg -v error -i "$1" -f rawvideo -pix_fmt rgb24 - | od -An -v -tu1 -w3; }
# fraction of pixels that differ from the most common colour (0 for a blank picture)
not_background() {
  ffmpeg -v error -i "$1" -vf scale=320:-2 -f rawvideo -pix_fmt rgb24 - | od -An -v -tu1 -w3 |
    awk '{ n[$0]++; t++ } END { m = 0; for (k in n) if (n[k] > m) m = n[k]; printf "%.4f\n", 1 - m / t }'
}
# rows and columns (first, last) holding at least 5 pixels of a colour class inside a rectangle
# of a W-wide image: box = the see-through shell, green/blue = the platform PCBs
extent() {  # file W x0 y0 x1 y1 class
  rgb "$1" | awk -v W="$2" -v X0="$3" -v Y0="$4" -v X1="$5" -v Y1="$6" -v C="$7" '
    { x = (NR - 1) % W; y = int((NR - 1) / W); r = $1; g = $2; b = $3
      if (x < X0 || x >= X1 || y < Y0 || y >= Y1) next
      hit = (C == "box" && b - r > 25 && g - r > 15 && b > 150) ||
            (C == "green" && g > r + 40 && g > b + 20) || (C == "blue" && b > r + 60 && b > g + 25)
      if (hit) { row[y]++; col[x]++ } }
    END { y0 = x0 = 1e9; y1 = x1 = -1
          for (y in row) if (row[y] >= 5) { if (y + 0 < y0) y0 = y + 0; if (y + 0 > y1) y1 = y + 0 }
          for (x in col) if (col[x] >= 5) { if (x + 0 < x0) x0 = x + 0; if (x + 0 > x1) x1 = x + 0 }
          print y0, y1, x0, x1 }'
}
# mean absolute difference of two images inside a rectangle, 0..255
diff_in() {  # a b W x0 y0 x1 y1
  paste -d' ' <(rgb "$1") <(rgb "$2") | awk -v W="$3" -v X0="$4" -v Y0="$5" -v X1="$6" -v Y1="$7" '
    { x = (NR - 1) % W; y = int((NR - 1) / W)
      if (x < X0 || x >= X1 || y < Y0 || y >= Y1) next
      s += ($1 > $4 ? $1 - $4 : $4 - $1) + ($2 > $5 ? $2 - $5 : $5 - $2) + ($3 > $6 ? $3 - $6 : $6 - $3); n += 3 }
    END { printf "%.3f\n", s / n }'
}
ge() { awk -v a="$1" -v b="$2" 'BEGIN { exit !(a >= b) }'; }

# ---- headless Chromium (fresh profile, no network, no GPU) ----
browse() {  # what (--dump-dom | --screenshot=FILE) url
  chromium --headless --no-sandbox --disable-gpu --disable-quic --no-first-run --disable-background-networking \
    --disable-component-update --disable-sync --hide-scrollbars --user-data-dir="$(mktemp -d -p "$work")" \
    --window-size=1280,1000 --virtual-time-budget=5000 "$1" "$2" 2>/dev/null
}
# a page with the look probe: lists elements that stick out of the page or clip their content,
# and images that did not load
cat > "$work/look.js" <<'JS'
window.addEventListener('load', () => {
  const W = document.documentElement.clientWidth, bad = [];
  for (const el of document.querySelectorAll('body *')) {
    const r = el.getBoundingClientRect(), cs = getComputedStyle(el);
    if (r.width === 0 && r.height === 0) continue;
    const clipped = cs.overflowX !== 'visible' && el.scrollWidth > el.clientWidth + 1;
    if (r.right > W + 1 || r.left < -1 || clipped)
      bad.push(el.tagName.toLowerCase() + ' [' + Math.round(r.left) + '..' + Math.round(r.right) + ' of ' + W + ']' +
               (clipped ? ' clips its content' : ''));
  }
  const broken = [...document.images].filter(i => !(i.complete && i.naturalWidth > 0)).map(i => i.src.slice(-60));
  const pre = document.createElement('pre');
  pre.id = 'look-result';
  pre.textContent = 'overflow ' + bad.length + ': ' + bad.slice(0, 10).join('; ') + '\nbroken ' + broken.length + ': ' +
                    broken.join('; ');
  document.body.appendChild(pre);
});
JS
look_page() {  # html-file label
  local probe="${1%.html}_look.html"
  sed 's#</body>#<script src="file://'"$work"'/look.js"></script></body>#' "$1" > "$probe"
  local result
  result=$(browse --dump-dom "file://$probe" | sed -n '/id="look-result"/,/<\/pre>/p')
  [ -n "$result" ] || fail "$2: Chromium did not load the page (no probe result)"
  grep -q "overflow 0:" <<< "$result" || fail "$2: elements overflow the page: $result"
  grep -q "broken 0:" <<< "$result" || fail "$2: images do not load: $result"
  browse --screenshot="$work/shot.png" "file://$1" >/dev/null
  local nb
  nb=$(not_background "$work/shot.png")
  ge "$nb" 0.02 || fail "$2: the screenshot is blank ($nb of the pixels differ from the background)"
  echo "ok: $2 (no overflow, images load, $nb of the screenshot is content)"
}

# ---- the demo's outputs (a short run that still locks on) ----
"$bin" demo --duration 150 --no-video --out "$work/demo" > "$work/demo.txt" 2>&1 ||
  fail "demo exit $?: $(cat "$work/demo.txt")"
look_page "$work/demo/report/report.html" "report.html"
est="$work/demo/estimate"
{
  echo '<!doctype html><html><head><meta charset="utf-8"><style>body{margin:8px;font-family:sans-serif}'
  echo 'img{display:block;max-width:100%}</style></head><body>'
  for f in fig4_bias fig5_allan fig9_attitude; do
    [ -s "$est/$f.png" ] || fail "$f.png was not drawn: $(grep -o "\"name\": \"$f\"[^}]*" "$est/summary.json")"
    nb=$(not_background "$est/$f.png")
    ge "$nb" 0.02 || fail "$f.png is blank ($nb)"
    echo "<h2>$f</h2><img src=\"$f.svg\"><img src=\"$f.png\">"
  done
  echo '</body></html>'
} > "$est/figures.html"
look_page "$est/figures.html" "figures (SVG and PNG)"

# ---- the video around a flip ----
log="$work/demo/sim/log.csv"
# the first flip after 70 s: the platform whose angle moves, and when
read -r t_flip plat < <(awk -F, '/^#/ { next } !h { for (i = 1; i <= NF; i++) c[$i] = i; h = 1; next }
  { p1 = $c["plat1_deg"]; p2 = $c["plat2_deg"]
    if (n++ && $1 > 70 && (p1 - q1 > 1 || q1 - p1 > 1 || p2 - q2 > 1 || q2 - p2 > 1)) {
      print $1, (p1 != q1 ? 1 : 2); exit }
    q1 = p1; q2 = p2 }' "$log")
[ -n "${t_flip:-}" ] || fail "no flip after 70 s in $log"
from=$(awk -v t="$t_flip" 'BEGIN { printf "%.2f", t - 3 }')
to=$(awk -v t="$t_flip" 'BEGIN { printf "%.2f", t + 4 }')
"$bin" render --log "$log" --out "$work/flip.mp4" --from "$from" --to "$to" --fps 10 --crf 12 > "$work/render.txt" 2>&1 ||
  fail "render: $(cat "$work/render.txt")"
frame() {  # index -> png (frame k shows t = from + k / 10 s)
  ffmpeg -v error -y -i "$work/flip.mp4" -vf "select=eq(n\,$1)" -vsync 0 -frames:v 1 "$work/f$1.png"
  echo "$work/f$1.png"
}
before=$(frame 5); still=$(frame 20); during=$(frame 36); later=$(frame 42); after=$(frame 68)
# the 3D view: left of the chart column, under the text band (docs/render.md, frame layout)
view="0 130 400 480"
read -r y0 y1 x0 x1 < <(extent "$before" 640 $view box)
height=$((y1 - y0 + 1))
[ "$height" -ge 240 ] || fail "the box spans $height px of the 480 px frame height (rows $y0..$y1); it should fill most of it"
[ "$x0" -gt 0 ] && [ "$x1" -lt 399 ] || fail "the box is cut at the side of the view (columns $x0..$x1)"
echo "ok: the box spans $height of 480 px (rows $y0..$y1, columns $x0..$x1)"
colour=$([ "$plat" = 1 ] && echo green || echo blue)
read -r py0 py1 px0 px1 < <(extent "$during" 640 $view "$colour")
[ "$py1" -ge 0 ] && [ $((py1 - py0 + 1)) -ge 120 ] ||
  fail "during the flip of platform $plat its $colour board spans rows $py0..$py1: not shown large"
echo "ok: platform $plat in close-up during its flip: rows $py0..$py1"
# around the platform (its board in the still frame, widened by 40 px): its axis triad and
# end-stop mark turn with it
read -r sy0 sy1 sx0 sx1 < <(extent "$still" 640 $view "$colour")
[ "$sy1" -ge 0 ] || fail "platform $plat's $colour board is not in view before its flip"
around="$((sx0 > 40 ? sx0 - 40 : 0)) $((sy0 > 170 ? sy0 - 40 : 130)) $((sx1 + 40 < 400 ? sx1 + 40 : 400)) $((sy1 + 40 < 480 ? sy1 + 40 : 480))"
quiet=$(diff_in "$before" "$still" 640 $around)
moved=$(diff_in "$still" "$after" 640 $around)
turning=$(diff_in "$during" "$later" 640 $view)
ge 1.0 "$quiet" || fail "the view changes by $quiet while nothing moves"
ge "$moved" 1.5 || fail "around platform $plat the view changes by only $moved from before its flip to after it"
ge "$moved" "$(awk -v q="$quiet" 'BEGIN { print 4 * q }')" || fail "flip change $moved is not well above the still change $quiet"
ge "$turning" 3 || fail "in close-up the view changes by only $turning while platform $plat turns"
echo "ok: around the platform the view changes by $moved across the flip and $quiet while still; $turning while it turns"
echo "look test passed"
