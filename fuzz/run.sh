#!/bin/bash
# Runs each fuzz target (or those named) for SECONDS (default 660) one after another, at the
# lowest priority, from the seeds of fuzz/seeds.py, and prints each one's executions and
# result. Crashes are written to fuzz/artifacts/TARGET/.
#   bash fuzz/run.sh [SECONDS] [TARGET...]
set -u
cd "$(dirname "$0")"
seconds=${1:-660}
shift || true
targets=${*:-mitsuba_xml ply serialized obj_mtl gltf exr hdr checkpoint}
[ -d corpus ] || python3 seeds.py
# Built once (release, debug assertions and overflow checks on, no sanitizer: the readers are
# safe Rust, what is sought is panics, hangs and memory), then each binary run as built.
nice -n 19 cargo +nightly fuzz build -O -a -s none || exit 1
bin=target/x86_64-unknown-linux-gnu/release
for t in $targets; do
  mkdir -p corpus/$t artifacts/$t logs
  nice -n 19 $bin/$t corpus/$t \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=262144 \
    -print_final_stats=1 -artifact_prefix=artifacts/$t/ > logs/$t.log 2>&1
  status=$?
  runs=$(grep -a "stat::number_of_executed_units" logs/$t.log | awk '{print $2}')
  echo "$t: exit $status, ${runs:-?} executions in ${seconds} s; $(ls artifacts/$t | wc -l) artifacts"
done
