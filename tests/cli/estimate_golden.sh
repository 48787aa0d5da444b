#!/usr/bin/env bash
# Golden test: `driftless estimate` on the committed golden log must reproduce the committed
# estimate.csv byte for byte. Change it on purpose with: DRIFTLESS_UPDATE_GOLDEN=1 bash $0 ...
set -euo pipefail
bin=$1; src=$2
golden=$src/tests/data/estimator_golden
out=$(mktemp -d); trap 'rm -rf "$out"' EXIT
"$bin" estimate --log "$golden/log.csv" --out "$out" --corrected > "$out/stdout.txt"
if [[ -n "${DRIFTLESS_UPDATE_GOLDEN:-}" ]]; then
  cp "$out/estimate.csv" "$golden/estimate.csv"
  echo "updated $golden/estimate.csv"
fi
if ! diff -q "$golden/estimate.csv" "$out/estimate.csv" > /dev/null; then
  echo "FAIL: estimate.csv differs from the golden output (first differences below)"
  diff "$golden/estimate.csv" "$out/estimate.csv" | head -10
  exit 1
fi
# the summary carries the documented keys
for key in attitude_drift_deg_per_h with_driftless without_driftless final_bias_dps final_sigma_dps \
           bias_error_rms_dps nees mean_band_95; do
  grep -q "\"$key\"" "$out/summary.json" || { echo "FAIL: summary.json lacks $key"; exit 1; }
done
# the estimate converged on the truth columns of the golden log (evaluation only)
jq -e '.truth.bias_error_rms_second_half_dps < 0.01 and .updates > 10 and .rejected == 0' \
  "$out/summary.json" > /dev/null || { echo "FAIL: golden run did not converge"; cat "$out/summary.json"; exit 1; }
# a second run is byte-identical (determinism)
"$bin" estimate --log "$golden/log.csv" --out "$out/again" --corrected > /dev/null
cmp -s "$out/corrected.csv" "$out/again/corrected.csv" || { echo "FAIL: rerun differs"; exit 1; }
echo "ok"
