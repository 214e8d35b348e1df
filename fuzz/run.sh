#!/bin/sh
# Fuzzes one target on one core for RUNS executions or SECONDS, whichever comes first, starting from
# its kept corpus (tests/corpus/fuzz/TARGET) and any seed folders given, then merges what it found
# back into the kept corpus, minimised (-merge=1): inputs cut to 1 KiB, and only inputs that reach
# new code edges (-use_counters=0: not every new hit count), so that it stays small. Findings are written as crash-*/timeout-*/oom-*
# files in the work folder (/tmp/drape-fuzz/TARGET/). Usage (after `make fuzz`):
#   fuzz/run.sh TARGET RUNS SECONDS [SEED_DIR...]     e.g. fuzz/run.sh obj 10000000 3600 tests/corpus/info
set -u
target=$1
runs=$2
seconds=$3
shift 3
binary=build-fuzz/fuzz_$target
kept=tests/corpus/fuzz/$target
work=${DRAPE_FUZZ_WORK:-/tmp/drape-fuzz}/$target
mkdir -p "$kept" "$work/corpus"
# Garment and motion files are larger than meshes; 64 KiB keeps whole patterns and short motions.
case $target in
  garment_json | garmentcode | dxf | bvh) max_len=65536 ;;
  *) max_len=16384 ;;
esac
options="-timeout=10 -rss_limit_mb=2048 -max_len=$max_len -artifact_prefix=$work/"
"$binary" -runs="$runs" -max_total_time="$seconds" $options -print_final_stats=1 "$work/corpus" "$kept" "$@"
status=$?
# Only what the fuzzer found and what was kept before are merged: seeds stay where they came from.
rm -rf "$work/merged" && mkdir -p "$work/merged"
"$binary" -merge=1 -use_counters=0 -timeout=10 -max_len=1024 "$work/merged" "$kept" "$work/corpus" || exit 1
rm -f "$kept"/* && cp "$work/merged"/* "$kept"/
echo "kept corpus: $(ls "$kept" | wc -l) files, $(du -sk "$kept" | cut -f1) KiB in $kept"
exit $status
