#!/usr/bin/env bash
# The house rules that a reader can check by grep (STYLE.md, README "Where things live"):
#  1. dependencies point one way (estimator/ needs only Eigen and std; the simulation core knows
#     nothing above it; nothing includes cli/);
#  2. no function in the product is over 150 lines;
#  3. each piece of shared physics is defined once: the old copies do not come back; every file
#     the program writes goes through the one output helper (estimator/output_file.hpp);
#     YAML is read and written only through twin/yaml_doc.hpp and the field tables (no block
#     parsed or emitted by hand with yaml-cpp);
#  4. the estimator tests have one closed-form generator; the twin-side test logs (tests/diagnose
#     headers) come from the twin's own sources (FastBox, Simulator), not from a copy of them.
# Usage: check.sh SOURCE_DIR. Prints every violation with file:line and exits 1 if there is one.
set -uo pipefail
src=${1:?usage: check.sh SOURCE_DIR}
cd "$src" || exit 2
bad=0
say() { echo "house: $*"; bad=1; }
product=(estimator twin diagnose calibration studies hil_bridge renders cli report importers)
files_in() { for d in "$@"; do [[ -d $d ]] && find "$d" -name '*.cpp' -o -name '*.hpp' | grep -v '^build'; done; }

# 1. dependency direction: "folder: folders it must not include"
check_includes() {
  local folder=$1; shift
  [[ -d $folder ]] || return 0
  local pattern
  pattern=$(printf '|%s/' "$@"); pattern="#include [\"<](${pattern:1})"
  while IFS= read -r hit; do say "$folder must not include that: $hit"; done \
    < <(grep -rnE "$pattern" "$folder" --include='*.cpp' --include='*.hpp')
}
check_includes estimator twin diagnose calibration studies hil_bridge renders cli report importers mujoco yaml-cpp fmt GL
check_includes twin diagnose calibration studies hil_bridge renders cli report
check_includes diagnose calibration studies hil_bridge renders cli
check_includes calibration diagnose studies hil_bridge renders cli
check_includes studies diagnose hil_bridge renders cli
check_includes hil_bridge diagnose calibration studies renders cli
check_includes renders diagnose calibration studies hil_bridge cli
check_includes report twin diagnose calibration studies hil_bridge renders cli
check_includes importers twin diagnose calibration studies hil_bridge renders cli

# 2. function length (Universal Ctags knows where each function ends); tests/house/long_functions.txt
#    lists the ones being split, and only shrinks
if command -v ctags > /dev/null; then
  mapfile -t all < <(files_in "${product[@]}")
  allowed=$(grep -v '^#' tests/house/long_functions.txt 2>/dev/null)
  long=$(ctags --languages=C++ --kinds-C++=f --fields=+ne -x --_xformat='%{end} %{line} %N %F' "${all[@]}" 2>/dev/null |
    awk '$1 ~ /^[0-9]+$/ && $1 - $2 + 1 > 150 { printf "%s %s %d %s\n", $4, $3, $1 - $2 + 1, $2 }')
  while read -r file fn lines at; do
    [[ -z $file ]] && continue
    key="$file ${fn%%[0-9a-f][0-9a-f][0-9a-f][0-9a-f][0-9a-f]*}"
    [[ $fn == __anon* ]] && key="$file __anon"
    grep -qxF "$key" <<< "$allowed" || say "function over 150 lines: $file:$at $fn ($lines lines)"
  done <<< "$long"
  while read -r file fn; do
    [[ -z $file ]] && continue
    grep -qE "^$file ${fn}" <<< "$long" ||
      say "tests/house/long_functions.txt lists $file $fn, which is no longer over 150 lines: delete the line"
  done <<< "$allowed"
else
  say "ctags (universal-ctags) is missing: function lengths not checked"
fi

# 3. one definition each: "home file | what | extended regex of a copy"
# (homes are space-separated; a hit inside a // comment does not count; compare_model.cpp settles
# the platforms on their stops once, a measurement, not a simulation loop)
while IFS='|' read -r homes what regex; do
  [[ -z $homes || $homes == \#* ]] && continue
  while IFS= read -r hit; do
    file=${hit%%:*}
    [[ " $homes " == *" $file "* ]] && continue
    code=${hit#*:*:}
    code=${code%%//*}
    grep -qE "$regex" <<< "$code" || continue
    say "$what belongs in ${homes%% *} only: $hit"
  done < <(grep -rnE "$regex" "${product[@]}" --include='*.cpp' --include='*.hpp' 2>/dev/null)
done <<'RULES'
estimator/geometry.hpp|rotation about an axis|AngleAxisd\([^)]*(kRadPerDeg|_deg|deg \*)
estimator/geometry.hpp|the quaternion log map|atan2\([^)]*\.w\(\)\)
estimator/geometry.hpp|the Earth rate|Vector3d\(0(\.0)?, *-?std::(cos|sin)\(
estimator/geometry.hpp|the eq. (5) flip cycle|\{ *\+1, *\+1, *-1, *-1 *\}|\{\{ *\+1, *\+1 *\}, *\{
estimator/mpu6050.hpp|the MPU6050 DLPF table|13\.4e-3|0\.0134|18\.6e-3
estimator/mpu6050.hpp|the MPU6050 sensitivities|131\.0, 65\.5|16384\.0|/ 340\.0|36\.53
estimator/output_file.hpp estimator/output_file.cpp|writing a file (use the output helper: partial name, checked writes, rename)|std::ofstream|fmt::output_file|fopen\(.*"[wa]
estimator/random.hpp estimator/random.cpp|the random generators|std::(normal|uniform_real)_distribution|std::mt19937|0x9E3779B97F4A7C15
estimator/attitude.hpp estimator/attitude.cpp estimator/attitude_comparison.hpp estimator/attitude_comparison.cpp|strapdown attitude integration (compare through est::run_estimate / AttitudeComparison)|AttitudeIntegrator
twin/world.cpp twin/world.hpp twin/simulator.cpp diagnose/compare_model.cpp|stepping the MuJoCo world (run the twin's Simulator with a Motion and, for outside flips, command_platform)|step_driven\(|mj_step[12]?\(
estimator/pipeline.cpp|NEES against the truth (score through est::run_estimate)|\.(llt|ldlt)\(\)\.solve\(e\)
estimator/fdi_input.cpp|the fault detector's input built from the filter (use est::fdi_input)|\.R_body_from_sensor[12] = 
twin/truth_delay.cpp twin/truth_delay.hpp|the sensors' sampling offset (model.time_offset_s: use twin::TruthDelay)|time_offset_s \* 
cli/compare_run.cpp|the options compare and diagnose share (use cli::add_compare_options)|"--(block|threshold|resample)"
importers/ground_truth.cpp|parsing EuRoC ground-truth stamps (use importers::read_ground_truth: whole ns)|_ns *= *v\[0\]|t_first_ns
twin/yaml_doc.cpp twin/yaml_doc.hpp|reading or writing YAML by hand (describe the block as a fields::Table, estimator/fields.hpp; twin/yaml_doc.hpp turns text into fields::Node and back)|yaml-cpp/yaml\.h|YAML::|\.as<(double|int|bool|std::string)>
RULES

# 4. one closed-form generator for the estimator tests (tests/estimator/synth.hpp, Eigen only):
#    no other header there draws its own samples
while IFS= read -r f; do say "a second closed-form generator: $f (extend tests/estimator/synth.hpp)"; done \
  < <(grep -lE "std::mt19937|normal_distribution" tests/estimator/*.hpp 2>/dev/null | grep -vx 'tests/estimator/synth.hpp')

# 5. the diagnose tests' logs come from the twin (FastBox or Simulator) or the independent Python
#    generator: no test header there runs the sensor model or integrates an attitude of its own
while IFS= read -r f; do say "a copy of the twin's generator: $f (build the log with twin::FastBox or the Simulator)"; done \
  < <(grep -lE "SensorModel [a-z_0-9]+[({]|\.step\([a-z_]+\)|AngleAxisd\([^)]*normalized" tests/diagnose/*.hpp 2>/dev/null)
exit $bad
