#!/usr/bin/env bash
# Minimises the corpus of one target (or of all) on edge coverage, keeping the hand-made
# files (seed_*, bad_*, regression_*) under their names: they go into the new corpus first,
# and libFuzzer's merge adds only the generated inputs that reach edges they do not.
#
#   fuzz/cmin.sh [TARGET...]     (from the workspace root; default: every target)
set -euo pipefail
cd "$(dirname "$0")/.."
targets=("$@")
[ ${#targets[@]} -eq 0 ] && targets=(model_json states_json params_toml scenario_toml motion_csv measured_csv)
for t in "${targets[@]}"; do
    cargo +nightly fuzz build "$t" >/dev/null 2>&1
    bin="fuzz/target/x86_64-unknown-linux-gnu/release/$t"
    old="fuzz/corpus/$t"
    new="$(mktemp -d)"
    find "$old" -maxdepth 1 -type f \( -name 'seed_*' -o -name 'bad_*' -o -name 'regression_*' \) \
        -exec cp {} "$new/" \;
    "$bin" -merge=1 -use_counters=0 -set_cover_merge=1 "$new" "$old" 2>&1 | grep -a 'MERGE-OUTER: [0-9]* new files' || true
    rm -rf "$old"
    mv "$new" "$old"
    chmod 755 "$old"
    echo "$t: $(find "$old" -type f | wc -l) files, $(cat "$old"/* | wc -c) bytes"
done
