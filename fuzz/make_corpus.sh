#!/usr/bin/env bash
# Writes the seed corpora of the fuzz targets through the codecs' own encoders
# (fuzz/make_corpus.cpp: one seed per servo command and per base / body frame kind), so no seed
# spells a frame's bytes by hand.
#   fuzz/make_corpus.sh [out_dir]     (default: $FUZZ_BUILD/seeds)
#     out_dir/fuzz_framer/    3-byte prefix (families, servo count, max chunk) + byte stream
#     out_dir/fuzz_decoders/  1-byte selector (family index + families * mode), servo count, frame
# Environment: FUZZ_BUILD (the clang fuzz build, default /tmp/fuzzbuild; configured if missing).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
build="${FUZZ_BUILD:-/tmp/fuzzbuild}"
out="${1:-$build/seeds}"

if [ ! -f "$build/CMakeCache.txt" ]; then
  CC="${CC:-clang}" CXX="${CXX:-clang++}" cmake -S "$here" -B "$build" \
    -DCMAKE_BUILD_TYPE=RelWithDebInfo >/dev/null
fi
cmake --build "$build" -j2 --target make_corpus -- --no-print-directory >/dev/null
# Start empty: a seed of a renamed or removed frame kind must not linger.
rm -rf "$out/fuzz_framer" "$out/fuzz_decoders"
"$build/make_corpus" "$out"
