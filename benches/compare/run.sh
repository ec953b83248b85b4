#!/usr/bin/env bash
# Side-by-side timing of mbs-core against native Pinocchio (C++, -O3 -march=native) on the
# 5-link planar chain and the 13-body branching tree: RNEA, CRBA and ABA. See README.md.
#
#   bash benches/compare/run.sh            # from any directory; ROUNDS=8 for more rounds
#
# Installs Eigen from Debian (libeigen3-dev) if missing, Pinocchio from PyPI (`pin`, pinned
# below) into target/compare/venv, compiles benches/compare/pinocchio_bench.cpp and the
# example mbs-core/examples/compare_timing.rs (target dir target/compare/cargo), runs them
# interleaved, checks that both compute the same numbers (1e-9 relative) and prints the
# table, also written to target/compare/table.md.
set -euo pipefail

PIN_VERSION=4.1.0
ROUNDS=${ROUNDS:-5}
VALUE_TOLERANCE=1e-9

ROOT=$(cd "$(dirname "${BASH_SOURCE[0]}")/../.." && pwd)
HERE=$ROOT/benches/compare
OUT=$ROOT/target/compare
VENV=$OUT/venv
mkdir -p "$OUT"

say() { printf '==> %s\n' "$*" >&2; }
die() { printf 'compare: %s\n' "$*" >&2; exit 1; }

as_root() {
    if [[ $EUID -eq 0 ]]; then "$@"; else sudo "$@"; fi
}

# --- Eigen, from Debian ----------------------------------------------------------------
EIGEN_INCLUDE=/usr/include/eigen3
if [[ ! -f $EIGEN_INCLUDE/Eigen/Core ]]; then
    say "installing libeigen3-dev"
    if ! as_root apt-get install -y libeigen3-dev; then
        as_root apt-get update
        as_root apt-get install -y libeigen3-dev
    fi
fi
[[ -f $EIGEN_INCLUDE/Eigen/Core ]] || die "Eigen headers not found in $EIGEN_INCLUDE"

# --- Pinocchio, from PyPI into a venv ----------------------------------------------------
if [[ ! -x $VENV/bin/python ]]; then
    say "creating $VENV"
    python3 -m venv "$VENV" || die "python3 -m venv failed (Debian: apt-get install python3-venv)"
fi
installed=$("$VENV/bin/python" -c 'import importlib.metadata as m; print(m.version("pin"))' \
    2>/dev/null || true)
if [[ $installed != "$PIN_VERSION" ]]; then
    say "pip install pin==$PIN_VERSION"
    "$VENV/bin/pip" install --quiet "pin==$PIN_VERSION"
fi

# The wheels (libpinocchio, cmeel-boost) carry the C++ headers under a cmeel prefix; ask
# the installed distributions where, rather than guessing the layout.
mapfile -t INCLUDES < <("$VENV/bin/python" - <<'EOF'
import importlib.metadata as m
import pathlib

def include_dir(dist, header):
    """The include directory of `dist` that holds `header` (as in `#include <header>`)."""
    for f in m.files(dist) or []:
        if str(f).endswith("include/" + header):
            path = pathlib.Path(f.locate()).resolve()
            return str(path.parents[header.count("/")])
    raise SystemExit(f"include/{header} not found in the {dist} wheel")

dirs = [include_dir("libpinocchio", "pinocchio/config.hpp"),
        include_dir("cmeel-boost", "boost/version.hpp")]
print("\n".join(dict.fromkeys(dirs)))
EOF
)
[[ ${#INCLUDES[@]} -gt 0 ]] || die "cannot locate Pinocchio's headers in $VENV"

# --- Compile the Pinocchio side (only when the source, flags or version changed) --------
# Header-only: without PINOCCHIO_ENABLE_TEMPLATE_INSTANTIATION every algorithm is
# instantiated in our translation unit with our flags, so nothing is linked from the wheel
# (its libpinocchio_default.so is built for generic x86-64). The BOOST_* definitions are
# those of the pinocchio::pinocchio_headers CMake target (the joint variant has more than
# Boost.MPL's default 20 alternatives).
CXXFLAGS=(-O3 -march=native -DNDEBUG -std=c++17
    -DBOOST_MPL_LIMIT_LIST_SIZE=30 -DBOOST_MPL_LIMIT_VECTOR_SIZE=30
    -DBOOST_MPL_CFG_NO_PREPROCESSED_HEADERS -DBOOST_FUSION_INVOKE_MAX_ARITY=12)
for dir in "${INCLUDES[@]}"; do CXXFLAGS+=(-isystem "$dir"); done
CXXFLAGS+=(-isystem "$EIGEN_INCLUDE")
PIN_BIN=$OUT/pinocchio_bench
STAMP="pin $PIN_VERSION; $(g++ --version | head -n1); g++ ${CXXFLAGS[*]}"
if [[ ! -x $PIN_BIN || $HERE/pinocchio_bench.cpp -nt $PIN_BIN
      || $(cat "$PIN_BIN.flags" 2>/dev/null) != "$STAMP" ]]; then
    say "compiling pinocchio_bench.cpp (a few minutes: all of Pinocchio's templates)"
    if ! g++ "${CXXFLAGS[@]}" "$HERE/pinocchio_bench.cpp" -o "$PIN_BIN" \
        >"$OUT/pinocchio_bench.log" 2>&1; then
        cat "$OUT/pinocchio_bench.log" >&2
        die "g++ failed (log above, also in $OUT/pinocchio_bench.log)"
    fi
    printf '%s\n' "$STAMP" >"$PIN_BIN.flags"
fi

# --- Build our side (cargo skips the build when nothing changed) ------------------------
# For the machine it runs on, as Pinocchio is (-march=native): OURS_RUSTFLAGS= (empty) builds
# for generic x86-64 instead. The flags are part of cargo's fingerprint, so changing them
# rebuilds.
OURS_RUSTFLAGS=${OURS_RUSTFLAGS--C target-cpu=native}
say "RUSTFLAGS='$OURS_RUSTFLAGS' cargo build --release -p mbs-core --example compare_timing"
(cd "$ROOT" && CARGO_TARGET_DIR=target/compare/cargo RUSTFLAGS="$OURS_RUSTFLAGS" \
    cargo build --quiet --release -p mbs-core --example compare_timing)
OURS_BIN=$OUT/cargo/release/examples/compare_timing

# --- Run, interleaved --------------------------------------------------------------------
RUN_DIR=$OUT/rounds
rm -rf "$RUN_DIR"
mkdir -p "$RUN_DIR"
LOAD_BEFORE=$(cut -d' ' -f1-3 /proc/loadavg)
for ((r = 1; r <= ROUNDS; r++)); do
    say "round $r/$ROUNDS: mbs-core"
    "$OURS_BIN" >"$RUN_DIR/ours.$r"
    say "round $r/$ROUNDS: Pinocchio"
    "$PIN_BIN" >"$RUN_DIR/pinocchio.$r"
done
LOAD_AFTER=$(cut -d' ' -f1-3 /proc/loadavg)

# --- Check the values, make the table ----------------------------------------------------
export ROUNDS RUN_DIR VALUE_TOLERANCE PIN_VERSION LOAD_BEFORE LOAD_AFTER OURS_RUSTFLAGS
export CPU=$(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//')
export CORES=$(nproc)
export RUSTC=$(rustc --version)
export GXX=$(g++ --version | head -n1)
"$VENV/bin/python" - "$OUT/table.md" <<'EOF'
import os
import statistics
import sys

rounds = int(os.environ["ROUNDS"])
run_dir = os.environ["RUN_DIR"]
tolerance = float(os.environ["VALUE_TOLERANCE"])

def parse(path):
    values, times = {}, {}
    with open(path) as f:
        for line in f:
            words = line.split()
            if words and words[0] == "value":
                values[(words[1], words[2])] = [float(x) for x in words[3:]]
            elif words and words[0] == "time":
                times[(words[1], words[2])] = float(words[3])
    return values, times

ours = [parse(f"{run_dir}/ours.{r}") for r in range(1, rounds + 1)]
theirs = [parse(f"{run_dir}/pinocchio.{r}") for r in range(1, rounds + 1)]

# Same numbers from both engines, in every round: inputs (proves the same state) and
# outputs (proves the same model).
failures, worst = [], {}
for r in range(rounds):
    ov, tv = ours[r][0], theirs[r][0]
    if set(ov) != set(tv):
        failures.append(f"round {r + 1}: quantities differ: {sorted(set(ov) ^ set(tv))}")
    for key in sorted(set(ov) & set(tv)):
        a, b = ov[key], tv[key]
        if len(a) != len(b):
            failures.append(f"{key[0]} {key[1]}: {len(a)} numbers (ours) vs {len(b)}")
            continue
        scale = max(max(abs(x) for x in b), 1e-300)
        rel = max(abs(x - y) for x, y in zip(a, b)) / scale
        worst[key] = max(worst.get(key, 0.0), rel)
        if rel > tolerance:
            failures.append(f"round {r + 1}: {key[0]} {key[1]} differs by {rel:.2e} "
                            f"(relative to its largest entry)\n  ours:      {a}\n"
                            f"  Pinocchio: {b}")
print("Values, max |ours - Pinocchio| / max |Pinocchio| over all rounds:", file=sys.stderr)
for (model, quantity), rel in sorted(worst.items()):
    print(f"  {model:8} {quantity:12} {rel:.1e}", file=sys.stderr)
if failures:
    print("\nVALUES DISAGREE: the two models are not the same.", file=sys.stderr)
    print("\n".join(failures), file=sys.stderr)
    sys.exit(1)

def median_range(xs):
    return statistics.median(xs), min(xs), max(xs)

rows = []
models = {"planar5": "5-link chain", "tree13": "13-body tree"}
# Pinocchio's default (local) convention against ours, then its world convention.
algorithms = [("rnea", "rnea", "RNEA"), ("crba", "crba", "CRBA"), ("aba", "aba", "ABA"),
              ("crba_world", "crba", "CRBA (Pinocchio WORLD convention)"),
              ("aba_world", "aba", "ABA (Pinocchio WORLD convention)")]
for model, model_name in models.items():
    for theirs_alg, ours_alg, alg_name in algorithms:
        p = [t[1][(model, theirs_alg)] for t in theirs]
        o = [t[1][(model, ours_alg)] for t in ours]
        ratio = [x / y for x, y in zip(p, o)]
        rows.append((model_name, alg_name, median_range(p), median_range(o),
                     median_range(ratio)))

def cell(m, lo, hi, digits):
    return f"{m:.{digits}f} ({lo:.{digits}f}–{hi:.{digits}f})"

lines = [
    f"Pinocchio {os.environ['PIN_VERSION']} (native C++, {os.environ['GXX']}, "
    f"-O3 -march=native) vs mbs-core ({os.environ['RUSTC']}, release profile, "
    f"RUSTFLAGS='{os.environ['OURS_RUSTFLAGS']}')",
    f"{os.environ['CPU']}, {os.environ['CORES']} cores; load average "
    f"{os.environ['LOAD_BEFORE']} before, {os.environ['LOAD_AFTER']} after; "
    f"{rounds} interleaved rounds, each the median of 30 batches.",
    "Median over rounds (min–max over rounds); values checked equal to "
    f"{tolerance:g} relative.",
    "",
    "| model | algorithm | Pinocchio µs | mbs-core µs | ratio Pinocchio / ours | ≥ 4× |",
    "|---|---|---|---|---|---|",
]
for model_name, alg_name, p, o, ratio in rows:
    lines.append(f"| {model_name} | {alg_name} | {cell(*p, 3)} | {cell(*o, 3)} | "
                 f"{cell(*ratio, 2)} | {'yes' if ratio[0] >= 4 else 'no'} |")
table = "\n".join(lines) + "\n"
with open(sys.argv[1], "w") as f:
    f.write(table)
print()
print(table)
EOF
say "table written to $OUT/table.md"
