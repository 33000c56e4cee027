#!/usr/bin/env bash
# A profile-guided build of `splitstream` and of decoder-core's
# `decode_timing` example (rustc's -Cprofile-generate / -Cprofile-use):
# both are built instrumented, run on a training set, and built again with
# the merged profile. Figures: encoder/BENCHMARKS.md, "Profile-guided builds".
#
#   encoder/benches/pgo.sh [PROFILE]     # PROFILE: release (default) or dist
#
# The training set leaves out the benchmarks' own inputs (the 1000 x 1000
# demo terrain, armadillo, the Jacksboro DEM), so that timing those measures
# the build and not a profile of the very run being timed: a 600 x 600 demo
# terrain, and bunny00 and refined_elephant from encoder/data/fetch.sh when
# they are there, in both position modes and both codecs. The binaries land
# in target/pgo-use/PROFILE/. Needs llvm-profdata from the toolchain's
# llvm-tools (`rustup component add llvm-tools-preview`).
set -euo pipefail

profile="${1:-release}"
case "$profile" in
release | dist) ;;
*)
    echo "pgo.sh: unknown profile '$profile' (release or dist)" >&2
    exit 2
    ;;
esac

root="$(cd "$(dirname "$0")/../.." && pwd)"
cd "$root"
host="$(rustc -vV | sed -n 's/^host: //p')"
profdata="$(rustc --print sysroot)/lib/rustlib/$host/bin/llvm-profdata"
if [[ ! -x "$profdata" ]]; then
    echo "pgo.sh: $profdata not found; run: rustup component add llvm-tools-preview" >&2
    exit 2
fi

data="$root/target/pgo-data"
work="$root/target/pgo-train"
rm -rf "$data" "$work"
mkdir -p "$data" "$work"

build() { # $1: target directory, $2: RUSTFLAGS
    CARGO_TARGET_DIR="$1" RUSTFLAGS="$2" cargo build --profile "$profile" \
        -p splitstream-encoder --bin splitstream \
        -p splitstream-decoder-core --features splitstream-decoder-core/alloc \
        --example decode_timing
}

echo "== instrumented build ($profile)"
build "$root/target/pgo-generate" "-Cprofile-generate=$data"
bin="$root/target/pgo-generate/$profile"

echo "== training"
"$bin/splitstream" demo --side 600 -o "$work/terrain.sps" >/dev/null
streams=("$work/terrain.sps")
real="$root/encoder/data/real"
for mesh in bunny00 refined_elephant; do
    if [[ -f "$real/$mesh.off" ]]; then
        "$bin/splitstream" encode "$real/$mesh.off" -o "$work/$mesh.sps" >/dev/null
        "$bin/splitstream" encode "$real/$mesh.off" -o "$work/$mesh-optimal.sps" \
            --position optimal >/dev/null
        "$bin/splitstream" encode "$real/$mesh.off" -o "$work/$mesh-deflate.sps" \
            --codec deflate >/dev/null
        streams+=("$work/$mesh.sps" "$work/$mesh-optimal.sps" "$work/$mesh-deflate.sps")
    else
        echo "   ($real/$mesh.off missing: run encoder/data/fetch.sh to train on it)"
    fi
done
for stream in "${streams[@]}"; do
    "$bin/examples/decode_timing" "$stream" 3 >/dev/null
    "$bin/splitstream" decode "$stream" -o "$work/decoded.ply" >/dev/null
done

echo "== merging"
"$profdata" merge -o "$work/merged.profdata" "$data"/*.profraw

echo "== optimised build ($profile)"
build "$root/target/pgo-use" "-Cprofile-use=$work/merged.profdata"
echo "done: target/pgo-use/$profile/splitstream, target/pgo-use/$profile/examples/decode_timing"
