#!/bin/bash
# tests/jobs/local_dir_test.sh PHNN — jobs/local.sh run from a study's own
# directory finds the sweep file there and writes results/ there (not into
# the repository); a sweep file that is not there is named, exit 2.
set -u
phnn=$(readlink -f "$1")
here=$(cd "$(dirname "$0")" && pwd)
repo=$(cd "$here/../.." && pwd)
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAILED: $*"; cat "$dir/log" 2>/dev/null; exit 1; }
cp "$repo/sweeps/tiny.toml" "$dir/my-study.toml"
cd "$dir" || exit 1
PHNN=$phnn timeout 300 bash "$repo/jobs/local.sh" my-study.toml 2 --quiet > "$dir/log" 2>&1 ||
  fail "jobs/local.sh my-study.toml 2 failed from the study's directory"
[[ -f $dir/results/my-study.h5 ]] || fail "no results/my-study.h5 in the study's directory"
[[ ! -e $repo/results/my-study.h5 ]] || fail "wrote into the repository's results/"
grep -q "| NODE-RK2 |" "$dir/log" || fail "no table printed"
PHNN=$phnn bash "$repo/jobs/local.sh" missing.toml 2 > "$dir/log" 2>&1
status=$?
[[ $status -eq 2 ]] || fail "a missing sweep file exited $status, expected 2"
grep -q "missing.toml: no such sweep file (from $dir)" "$dir/log" || fail "the missing file is not named"
echo "PASSED: jobs/local.sh from a study directory"
