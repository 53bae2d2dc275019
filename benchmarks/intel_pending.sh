#!/usr/bin/env bash
# The issue-24 rows not yet measured on the lent machines' Intel Xeon, in one device call:
#
#   run(command="bash benchmarks/intel_pending.sh", carry=[".whl", ".pinocchio"], timeout_s=540)
#
# .whl holds the peers' pure-Python wheels (pint, sippy, control, …), .pinocchio the bundle that
# benchmarks/pinocchio_bundle.sh builds for the target's Python. Writes into $OUT (else a new
# temporary folder): machine.txt (CPU, versions, which Pinocchio was imported), rls/results.md
# and .json (`run.py --only rls`: batch RLS with and without history, streaming update, against
# a plain numba RLS), ab_rls_wrapper.txt (the pieces of RLS.run(store=False)), ab_one_state.txt
# (three processes of benchmarks/ab_one_state.py: one-state CRBA and RNEA against pin.crba and
# pin.rnea), cli_identify_arx.txt (benchmarks/cli_identify_arx.py) and sweep_loaded.txt
# (benchmarks/bench_sweep_auto.py on a loaded 2-core machine: the sweep and three busy loops
# share cores 2 and 3, NUMBA_NUM_THREADS=2). The single-thread rows run on core 8, away from the
# busy loops, which start first so that the 1-minute load average has built up by the sweep.
# import_time.txt: where `import gripkit` spends its time there. STEPS="crba import" (say) runs
# only those rows. Every step runs even if one before it fails.
set -u
OUT="${OUT:-$(mktemp -d)}"
mkdir -p "$OUT"
cd "$(dirname "$0")/.."
export OPENBLAS_NUM_THREADS=1 OMP_NUM_THREADS=1 MKL_NUM_THREADS=1
py="${PYTHON:-$(command -v python3 || command -v python)}"
ver="$("$py" -c 'import sys; print(f"{sys.version_info[0]}.{sys.version_info[1]}")')"
site="$(mktemp -d)"
if ls .whl/*.whl > /dev/null 2>&1; then
    "$py" -m pip install --no-deps --target "$site" -q .whl/*.whl
fi
bundle=".pinocchio/pinocchio-cp${ver/./}.tar.xz"
pinsite=""
if [ -f "$bundle" ]; then
    tar -C "$site" -xJf "$bundle" && pinsite=":$site/cmeel.prefix/lib/python$ver/site-packages"
else
    echo "no $bundle: the CRBA rows need it (bash benchmarks/pinocchio_bundle.sh $ver)" >&2
fi
# the bundle first: it must be the Pinocchio imported, not one installed beside this Python
export PYTHONPATH="$PWD/src:$PWD/benchmarks${pinsite}:$site"
{
    lscpu | grep -E 'Model name|^CPU\(s\)|Flags' | cut -c1-200
    "$py" -c 'import sys, numpy, scipy, numba; print(sys.version.split()[0], "numpy",
numpy.__version__, "scipy", scipy.__version__, "numba", numba.__version__)'
    "$py" -c 'import pinocchio; print("pinocchio", pinocchio.__version__, pinocchio.__file__)'
    uptime
    # SOURCE: the commit sent, given in the command (the device copy's .git may lag the tree)
    echo "source: ${SOURCE:-$(git rev-parse HEAD 2> /dev/null || echo "not a git checkout")}"
} > "$OUT/machine.txt" 2>&1
cpu="$(lscpu | sed -n 's/^Model name: *//p')"
# STEPS: which rows to run (default all): rls wrapper crba cli import sweep
want() { [[ " ${STEPS:-rls wrapper crba cli import sweep} " == *" $1 "* ]]; }
# cores: ONE_CORE for the single-thread rows, PAIR for the loaded sweep (defaults 8 and 2,3)
one="taskset -c ${ONE_CORE:-8}" pair="taskset -c ${PAIR:-2,3}"
command -v taskset > /dev/null || { one="" pair=""; echo "no taskset: rows not pinned" >&2; }
hogs=()
if want sweep; then
    for i in 1 2 3; do
        $pair bash -c 'while :; do :; done' &
        hogs+=($!)
    done
fi
trap '[ ${#hogs[@]} -eq 0 ] || kill "${hogs[@]}" 2> /dev/null' EXIT
reports=("$OUT/machine.txt")
# CRBA first: its minute also lets a freshly started machine settle before the RLS rows
if want crba; then
    {
        echo "# CPU: $cpu; ${CRBA_RUNS:-3} processes of benchmarks/ab_one_state.py, 9 rounds each;" \
            "$(uptime)"
        for ((i = 0; i < ${CRBA_RUNS:-3}; i++)); do
            $one "$py" benchmarks/ab_one_state.py . 9
        done
    } > "$OUT/ab_one_state.txt" 2>&1
    reports+=("$OUT/ab_one_state.txt")
fi
if want rls; then  # RLS_RUNS runs (default 1): rls/results.md and .json, then rls-2.md, …
    for ((i = 1; i <= ${RLS_RUNS:-1}; i++)); do
        $one "$py" benchmarks/run.py --only rls --out "$OUT/rls-run"
        if [ "$i" -eq 1 ]; then
            mv "$OUT/rls-run" "$OUT/rls" && reports+=("$OUT/rls/results.md")
        else
            mv "$OUT/rls-run/results.md" "$OUT/rls-$i.md" && reports+=("$OUT/rls-$i.md")
            rm -rf "$OUT/rls-run"
        fi
    done
fi
if want wrapper; then
    { echo "# CPU: $cpu"; $one "$py" benchmarks/ab_rls_wrapper.py; } > "$OUT/ab_rls_wrapper.txt" 2>&1
    reports+=("$OUT/ab_rls_wrapper.txt")
fi
if want cli; then
    $one "$py" benchmarks/cli_identify_arx.py 9 > "$OUT/cli_identify_arx.txt" 2>&1
    reports+=("$OUT/cli_identify_arx.txt")
fi
if want import; then
    # where `import gripkit` spends its time here: the 25 largest cumulative entries
    {
        echo "# CPU: $cpu; python -X importtime -c 'import gripkit' (second run), us"
        $one "$py" -X importtime -c 'import gripkit' 2> /dev/null
        $one "$py" -X importtime -c 'import gripkit' 2>&1 | sort -t'|' -k2 -n -r | head -25
        for mod in numpy scipy numba gripkit; do
            /usr/bin/time -f "import $mod: %e s wall" $one "$py" -c "import $mod"
        done
    } > "$OUT/import_time.txt" 2>&1
    reports+=("$OUT/import_time.txt")
fi
if want sweep; then
    {
        echo "# CPU: $cpu; cores ${PAIR:-2,3} shared with 3 busy loops; before: $(uptime)"
        NUMBA_NUM_THREADS=2 $pair "$py" benchmarks/bench_sweep_auto.py 2> "$OUT/sweep.err"
        echo "# after: $(uptime)"
        tail -n 3 "$OUT/sweep.err"
    } > "$OUT/sweep_loaded.txt" 2>&1
    rm -f "$OUT/sweep.err"
    reports+=("$OUT/sweep_loaded.txt")
fi
cat "${reports[@]}"
