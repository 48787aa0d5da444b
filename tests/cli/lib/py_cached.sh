#!/usr/bin/env bash
# (in lib/, so that the cli tests' *.sh glob does not take it for a test)
# python3 for the cli tests' log generators (tests/estimator/navgen.py, tests/diagnose/*.py), with
# the logs they write kept for the other test suite of the same CI run: CI runs every script twice,
# in the Release suite and in the sanitizer suite, and the generators (pure Python, no code of ours)
# took about a third of the sanitizer suite's script CPU making the same logs again.
#
# usage: py_cached.sh SCRIPT ARGS...   (as python3 SCRIPT ARGS...)
# With DRIFTLESS_GEN_CACHE naming a folder (.ci/run sets it), a run whose outputs are all named by
# --out or --NAME-out options is looked up by a key of: the Python, the script's text, every
# argument but the output paths (and each output's file extension), and the contents of every
# argument that names an existing file (mutate.py's input log). A hit unpacks the outputs and replays
# what the run printed; a miss runs it and, when it exits 0, keeps its outputs and its output text.
# Two runs of one key at once: the second waits for the first (a lock per key), then unpacks.
# Without DRIFTLESS_GEN_CACHE, or with no output option, it runs python3 as it is.
set -uo pipefail
python=/usr/bin/python3
cache=${DRIFTLESS_GEN_CACHE:-}
# the logs are kept compressed (zstd -1: 767 MB of logs in 151 MB over the 48 cli scripts)
[[ -n $cache && $# -ge 1 && -f $1 ]] && command -v zstd > /dev/null || exec "$python" "$@"

outs=()
key_text="py_cached v1"$'\n'"$python"$'\n'
key_text+="$(sha256sum < "$1")"$'\n'
args=("$@")
for (( i = 1; i < ${#args[@]}; ++i )); do
  a=${args[i]}
  if [[ $a == --out || $a == --*-out ]] && (( i + 1 < ${#args[@]} )); then
    path=${args[i + 1]}
    outs+=("$path")
    ext=${path##*/}; [[ $ext == *.* ]] && ext=${ext##*.} || ext=
    key_text+="$a <output .$ext>"$'\n'
    (( ++i ))
    continue
  fi
  key_text+="arg $a"$'\n'
  [[ -f $a ]] && key_text+="contents $(sha256sum < "$a")"$'\n'
done
(( ${#outs[@]} > 0 )) || exec "$python" "$@"
mkdir -p "$cache" || exec "$python" "$@"
key=$(printf '%s' "$key_text" | sha256sum | cut -c1-32)
entry=$cache/$key

exec {lock}> "$entry.lock"
flock "$lock"
if [[ -f $entry.done ]]; then
  for k in "${!outs[@]}"; do zstd -d -q -f "$entry.out$k.zst" -o "${outs[k]}" || exit 1; done
  cat "$entry.stdout"
  cat "$entry.stderr" >&2
  exit 0
fi
"$python" "$@" > "$entry.stdout.tmp" 2> "$entry.stderr.tmp"
status=$?
cat "$entry.stdout.tmp"
cat "$entry.stderr.tmp" >&2
if (( status == 0 )); then
  kept=1
  for k in "${!outs[@]}"; do
    zstd -1 -q -f "${outs[k]}" -o "$entry.out$k.tmp" 2> /dev/null && mv "$entry.out$k.tmp" "$entry.out$k.zst" || kept=0
  done
  if (( kept )); then
    mv "$entry.stdout.tmp" "$entry.stdout" && mv "$entry.stderr.tmp" "$entry.stderr" && touch "$entry.done"
  fi
fi
rm -f "$entry".*.tmp   # what a failed copy (a full disk) left
exit "$status"
