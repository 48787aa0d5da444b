#!/usr/bin/env bash
# Each shared helper is defined once (issue 11): this script greps the product sources for old
# hand-written copies and fails naming file and line. Run by CTest (house.one_definition).
# Usage: tests/house/one_definition.sh [SOURCE_ROOT]
set -uo pipefail
root=${1:-$(cd "$(dirname "$0")/../.." && pwd)}
cd "$root" || exit 2
folders=(estimator twin calibration studies diagnose hil_bridge renders report importers cli)
existing=()
for d in "${folders[@]}"; do [[ -d $d ]] && existing+=("$d"); done

fail=0
# check PATTERN ALLOWED_REGEX WHAT: PATTERN (extended regex) may only occur in files matching ALLOWED_REGEX
check() {
  local pattern=$1 allowed=$2 what=$3 hits
  hits=$(grep -rnE --include='*.cpp' --include='*.hpp' -- "$pattern" "${existing[@]}" | grep -vE "^($allowed):" || true)
  if [[ -n $hits ]]; then
    echo "FAIL: $what; found outside ${allowed}:"
    echo "$hits" | sed 's/^/  /'
    fail=1
  fi
}

# log metadata: one writer (estimator/log_metadata.*), exact numbers; std::to_string cut hinge axes
check '\.set\("[a-z0-9_]+", *(std::to_string|fmt::format)' 'estimator/log_metadata\.cpp' \
  'log metadata written by hand (use log::LogInfo / write_log_info / set_number)'
# numbers written for machines: one exact formatter (estimator/numbers.*)
check 'precision\(17\)|\{:\.17g\}|chars_format::general' 'estimator/numbers\.cpp' \
  'a second exact-number formatter (use exact_number)'
# units: one table (estimator/units.cpp)
check '\{"dps_rthz"|\{"dph", |"deg/s\^2", "deg/s2"' 'estimator/units\.cpp' 'a second unit table'
# user input errors: one type (estimator/input_error.hpp); a failed write (io::OutputError) is not input
check 'class [A-Za-z]+ *: *public std::(runtime_error|invalid_argument)' 'estimator/input_error\.hpp|renders/gl_context\.hpp|estimator/output_file\.hpp' \
  'a new exception type for user input (use driftless::InputError)'

# report plumbing (report/): one gnuplot runner, one JSON escaper and number, one HTML escaper
check "gnuplot '|gnuplot \"" 'report/gnuplot\.cpp' 'a second gnuplot runner (use report::render)'
check 'std::string (esc_json|json_string|json_num|json_number|esc_html|html_escape|base64)\(' \
  'report/(json|html)\.(cpp|hpp)' 'a second JSON/HTML escaper or JSON number (use report/json.hpp, report/html.hpp)'
check '\{:\.9g\}|%\.9g|%\.17g' 'estimator/numbers\.cpp' 'a second machine-number formatter (use exact_number / json_number)'

if [[ $fail -ne 0 ]]; then exit 1; fi
echo "ok: each checked helper is defined once"
