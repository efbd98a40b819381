#!/bin/bash
# Exploratory runs: each target SECONDS in a forked child that goes on after a crash, a hang
# or running out of memory (each written to artifacts/TARGET/), to find many at once.
#   bash fuzz/explore.sh [SECONDS] [TARGET...]
set -u
cd "$(dirname "$0")"
seconds=${1:-300}
shift || true
targets=${*:-mitsuba_xml ply serialized obj_mtl gltf exr hdr checkpoint}
[ -d corpus ] || python3 seeds.py
nice -n 19 cargo +nightly fuzz build -O -a -s none || exit 1
bin=target/x86_64-unknown-linux-gnu/release
for t in $targets; do
  mkdir -p corpus/$t artifacts/$t logs
  nice -n 19 $bin/$t corpus/$t -fork=1 -ignore_crashes=1 -ignore_ooms=1 -ignore_timeouts=1 \
    -max_total_time="$seconds" -timeout=10 -rss_limit_mb=2048 -max_len=262144 \
    -artifact_prefix=artifacts/$t/ > logs/$t.explore.log 2>&1
  echo "$t: exit $?, $(ls artifacts/$t | wc -l) artifacts"
done
