#!/bin/bash
# tests/jobs/git_commit_test.sh CMAKE — cmake/git_commit.cmake on a scratch
# repository: the commit, "-dirty" after an edit of a tracked file (not for
# a touched but unchanged one), the new commit after a commit, "unknown"
# outside git, and the header rewritten only when its text changes.
set -u
cmake=$1
script=$(cd "$(dirname "$0")/../.." && pwd)/cmake/git_commit.cmake
dir=$(mktemp -d)
trap 'rm -rf "$dir"' EXIT
fail() { echo "FAILED: $*"; cat "$dir/h" 2>/dev/null; exit 1; }
run() { "$cmake" -DSOURCE_DIR="$1" -DOUT="$dir/h" -P "$script" || fail "the script failed"; }
defined() { sed -n 's/^#define PHNN_GIT_COMMIT "\(.*\)"$/\1/p' "$dir/h"; }
mkdir "$dir/repo" "$dir/plain"
cd "$dir/repo" || exit 1
git init -q && git config user.email t@t && git config user.name t
echo a > f && git add f && git commit -qm one
run "$dir/repo"
[[ $(defined) == $(git rev-parse HEAD) ]] || fail "clean tree: '$(defined)'"
before=$(stat -c %Y.%N "$dir/h" 2>/dev/null || stat -c %Y "$dir/h")
sleep 1.1; touch f; run "$dir/repo"
[[ $(defined) == $(git rev-parse HEAD) ]] || fail "a touched, unchanged file made it '$(defined)'"
[[ $(stat -c %Y "$dir/h") == "${before%%.*}" ]] || fail "the header was rewritten without a change"
echo b > f; run "$dir/repo"
[[ $(defined) == "$(git rev-parse HEAD)-dirty" ]] || fail "edited tree: '$(defined)'"
git commit -qam two; run "$dir/repo"
[[ $(defined) == $(git rev-parse HEAD) ]] || fail "after the commit: '$(defined)'"
run "$dir/plain"
[[ $(defined) == unknown ]] || fail "outside git: '$(defined)'"
echo "PASSED: git commit, -dirty, refresh, unknown"
