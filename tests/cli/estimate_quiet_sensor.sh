#!/usr/bin/env bash
# A sensor much quieter than the defaults (issue 13 item 4): an ADIS16470 and a FOG from the
# outsider's generator (tests/estimator/navgen.py, apart from twin/), static box, estimated with the
# MPU6050 defaults, read NIS means of 0.29 and 0.02 against a band of 2.1-4.0. The note
# noise_overstated stays a note (safe: exit 0, also under --strict) but names the factor by which the
# configured noise is too large, 1 / sqrt(NIS per dof) as a sigma, and the fix --tune auto; with
# --tune auto the ADIS16470's NIS is inside its band, and a run that used --tune auto and still reads
# a low NIS (the FOG: the random walk's upper bound) is not told to use it.
set -euo pipefail
bin=$1; src=$2
source "$src/tests/cli/lib/outsider_log.sh"
gen=$src/tests/estimator/navgen.py

finding() { jq -c --arg c noise_overstated '[.health.findings[] | select(.cause == $c)]' "$1/summary.json"; }
for sensor in adis16470 fog; do
  "$py" "$gen" --out "$t/$sensor.csv" --sensor "$sensor" --duration 600 --seed 3 > /dev/null 2>&1
  rc=0
  "$bin" estimate --log "$t/$sensor.csv" --out "$t/o_$sensor" --strict > "$t/$sensor.txt" 2>&1 || rc=$?
  [[ $rc -eq 0 ]] || { cat "$t/$sensor.txt"; fail "$sensor: --strict exited $rc on a note"; }
  f=$(finding "$t/o_$sensor")
  jq -e 'length == 1 and .[0].severity == "ok"' <<< "$f" > /dev/null || fail "$sensor: no noise_overstated note: $f"
  text=$(jq -r '.[0].text' <<< "$f")
  grep -qF "use --tune auto" <<< "$text" || fail "$sensor: the note does not name --tune auto: $text"
  # the factor printed is 1 / sqrt(NIS per dof) of summary.json, to its two digits
  want=$(jq -r '.health | 1 / ((.nis_mean / .nis_dof_mean) | sqrt)' "$t/o_$sensor/summary.json")
  got=$(sed -n 's/.*the configured noise is \([0-9.e+]*\)x too large as a sigma.*/\1/p' <<< "$text")
  [[ -n $got ]] || fail "$sensor: no factor in: $text"
  awk -v g="$got" -v w="$want" 'BEGIN { exit !(g > 0.95 * w && g < 1.05 * w && w > 2) }' ||
    fail "$sensor: factor $got, expected $want (> 2: these sensors are far quieter than the defaults)"
  grep -qF "configured noise is ${got}x too large" "$t/$sensor.txt" || fail "$sensor: the console does not say it"
done

# the fix works: with --tune auto the ADIS16470's NIS is inside its band, no note
"$bin" estimate --log "$t/adis16470.csv" --out "$t/o_adis_tuned" --tune auto > /dev/null 2>&1
jq -e '.health | .nis_mean >= .nis_mean_band_95[0] and .nis_mean <= .nis_mean_band_95[1]' \
  "$t/o_adis_tuned/summary.json" > /dev/null || { jq .health "$t/o_adis_tuned/summary.json"; fail "adis16470 --tune auto: NIS outside its band"; }
[[ $(finding "$t/o_adis_tuned") == "[]" ]] || fail "adis16470 --tune auto: still a noise_overstated note"

# a run that used --tune auto is not told to use it
"$bin" estimate --log "$t/fog.csv" --out "$t/o_fog_tuned" --tune auto > /dev/null 2>&1
f=$(finding "$t/o_fog_tuned")
jq -e 'length == 1' <<< "$f" > /dev/null || fail "fog --tune auto: expected the note (NIS below its band): $f"
if jq -r '.[0].text' <<< "$f" | grep -F -- "--tune auto"; then fail "fog --tune auto: the note names --tune auto"; fi
jq -r '.[0].text' <<< "$f" | grep -qF "measured from this log already" || fail "fog --tune auto: no alternative: $f"
echo "ok"
