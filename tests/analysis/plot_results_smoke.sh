#!/bin/sh
# Smoke test of analysis/plot_results.py: build a synthetic results file with every run status
# (tests/analysis/make_fixture.py), plot it, and check that each kind of figure was written;
# first the unit tests of the scripts' choices (tests/analysis/test_plot_results.py,
# test_paper_claims.py, test_cost_model_check.py, test_schedule_replay.py,
# test_compare_ablation.py, test_adaptive_cost.py, test_rule_variants.py, test_plot_eval_errors.py,
# test_arx_baseline.py, test_rounds_replay.py: with the phnn binary given, else $PHNN or
# build/phnn, it also trains a small adaptive sweep, ~3 s; without one that part is skipped).
# ctest: add_test(NAME plot_results_smoke COMMAND sh ${CMAKE_SOURCE_DIR}/tests/analysis/plot_results_smoke.sh)
#        set_tests_properties(plot_results_smoke PROPERTIES SKIP_RETURN_CODE 77)
# Then, with a phnn binary, a real results file with stored weights: the energy figure (phnn eval).
#   tests/analysis/plot_results_smoke.sh [PYTHON [PHNN]]   (default /usr/bin/python3, Debian h5py+mpl)
set -eu
here=$(cd "$(dirname "$0")" && pwd)
root=$(cd "$here/../.." && pwd)
py=${1:-/usr/bin/python3}
# 77 = skipped (ctest SKIP_RETURN_CODE) when the Debian packages are not installed
"$py" -c "import h5py, matplotlib, numpy, pandas" 2>/dev/null || { echo "h5py/matplotlib/pandas missing: skipped"; exit 77; }
out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
"$py" "$here/test_plot_results.py"
"$py" "$here/test_paper_claims.py"
"$py" "$here/test_cost_model_check.py"
"$py" "$here/test_schedule_replay.py"
"$py" "$here/test_compare_ablation.py"
"$py" "$here/test_adaptive_cost.py"
"$py" "$here/test_rule_variants.py"
"$py" "$here/test_plot_eval_errors.py"
"$py" "$here/test_arx_baseline.py"
PHNN="${2:-${PHNN:-$root/build/phnn}}" "$py" "$here/test_rounds_replay.py"
"$py" "$here/make_fixture.py" "$out/fixture.h5"
"$py" "$root/analysis/plot_results.py" "$out/fixture.h5" "$out/fig"
for f in mse_I_harmonic mse_II_duffing mse_III_duffing trajectories_harmonic \
         trajectories_sizes_duffing jacobian_duffing loss_harmonic time_vs_error_duffing; do
    test -s "$out/fig/$f.png" || { echo "missing $f.png" >&2; exit 1; }
    test -s "$out/fig/$f.pdf" || { echo "missing $f.pdf" >&2; exit 1; }
    test -s "$out/fig/$f.caption.txt" || { echo "missing $f.caption.txt" >&2; exit 1; }
done
head -c 5 "$out/fig/mse_I_harmonic.pdf" | grep -q '%PDF-' || { echo "mse_I_harmonic.pdf: not a PDF" >&2; exit 1; }
if [ $# -ge 2 ]; then
    "$2" train --system duffing --model phnn-s-dg --n-train 25 --seeds 0-2 --steps 20 \
        --eval-every 10 --quiet --out "$out/trained.h5" > /dev/null
    PHNN="$2" "$py" "$root/analysis/plot_results.py" "$out/trained.h5" "$out/fig2"
    test -s "$out/fig2/energy_duffing.png" || { echo "missing energy_duffing.png" >&2; exit 1; }
    # A system file (4 states, named q1 p1 q2 p2, three phase pairs): trajectories and energy.
    "$2" train --system "$root/sweeps/systems/coupled-duffing.toml" --model phnn-s-rk2 \
        --n-train 25 --seeds 0-1 --steps 20 --eval-every 10 --quiet --out "$out/file.h5" > /dev/null
    PHNN="$2" "$py" "$root/analysis/plot_results.py" "$out/file.h5" "$out/fig3" > "$out/fig3.log"
    for f in trajectories_coupled-duffing energy_coupled-duffing mse_grid_coupled-duffing; do
        test -s "$out/fig3/$f.png" || { echo "missing $f.png" >&2; cat "$out/fig3.log" >&2; exit 1; }
    done
    # analysis/results.py: pandas on real files (pending runs, traces, exact numbers).
    PHNN="$2" "$py" "$here/test_results_loader.py"
    # compare_ablation.py: a file against itself is one row per cell, every verdict "~".
    PHNN="$2" "$py" "$root/analysis/compare_ablation.py" "$out/trained.h5" "self=$out/trained.h5" \
        > "$out/ablation.md"
    grep -q '^| duffing | PHNN-S-DG | 25 | .* \[.*/3\] | .* ~ |$' "$out/ablation.md" \
        || { echo "compare_ablation.py: unexpected table" >&2; cat "$out/ablation.md" >&2; exit 1; }
    # paper_claims.py on one cell without studies: the header, no comparison, the studies skipped.
    PHNN="$2" "$py" "$root/analysis/paper_claims.py" "$out/trained.h5" > "$out/claims.md"
    grep -q '^# The paper.s statements checked on trained.h5$' "$out/claims.md" \
        && grep -q '^Not in the file (statements skipped): Study I, II, III.$' "$out/claims.md" \
        || { echo "paper_claims.py: unexpected output" >&2; cat "$out/claims.md" >&2; exit 1; }
    # schedule_replay.py on a sweep measured by its own results: one table row per rank count.
    "$2" sweep "$root/sweeps/tiny.toml" --out "$out/tiny.h5" --quiet > /dev/null 2>&1
    PHNN="$2" "$py" "$root/analysis/schedule_replay.py" "$root/sweeps/tiny.toml" 1,2 \
        "$root/sweeps/tiny.toml" "$out/tiny.h5" > "$out/replay.md"
    grep -q '^measured / estimated from .*tiny.h5: 2 cells (0 left out: runs missing)$' "$out/replay.md" \
        && grep -q '^| 1 | 2 | 100.0 % | 100.0 % | 100.0 % |$' "$out/replay.md" \
        && grep -q '^| 2 | ' "$out/replay.md" \
        || { echo "schedule_replay.py: unexpected output" >&2; cat "$out/replay.md" >&2; exit 1; }
    # The comparisons of the shipped adaptive sweeps are what paper_claims.py writes for their
    # grids (a sweep stopped at once: every run pending, every cell listed).
    for f in paper-adaptive paper-adaptive-both paper-adaptive-study1 paper-adaptive-study1-lean; do
        # Stopped once the file exists (a stop while it generates the data writes none).
        "$2" sweep "$root/sweeps/$f.toml" --out "$out/$f.h5" > /dev/null 2>&1 & pid=$!
        for _ in $(seq 1 1200); do [ -f "$out/$f.h5" ] && break; sleep 0.1; done
        kill -TERM "$pid" 2>/dev/null || true
        wait "$pid" || true
        PHNN="$2" "$py" "$root/analysis/paper_claims.py" "$out/$f.h5" --write-comparisons > "$out/$f.cmp"
        grep -q '^  \["' "$out/$f.cmp" || { echo "$f: no comparison written" >&2; exit 1; }
        sed -n '/^comparisons = \[/,/^\]/p' "$root/sweeps/$f.toml" | diff - "$out/$f.cmp" > /dev/null \
            || { echo "sweeps/$f.toml: comparisons differ from paper_claims.py's" >&2; exit 1; }
    done
    # plot_results.py on an adaptive file draws only the runs its rounds asked for.
    PHNN="$2" "$py" "$root/analysis/plot_results.py" "$out/paper-adaptive-study1.h5" "$out/fig4" \
        > "$out/fig4.log" 2>&1 || { cat "$out/fig4.log" >&2; exit 1; }
    grep -q "pending of 450 runs" "$out/fig4.log" \
        || { echo "plot_results.py: not the 450 runs of round 0" >&2; cat "$out/fig4.log" >&2; exit 1; }
fi
echo "plot_results smoke test passed"
