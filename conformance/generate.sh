#!/usr/bin/env bash
# Regenerates the conformance vector set conformance/vectors/<version>/
# (streams and manifest.json) with `splitstream-conformance generate`.
#
# The vectors are never edited by hand: change the generator
# (conformance/src/generate/) and run this script. Output is byte-identical
# on every run and machine; `cargo test -p splitstream-conformance` checks
# that the committed files match a fresh generation.
#
# One vector (bunny-npm) is encoded from a real mesh, encoder/data/real/bunny.ply,
# which is not committed: encoder/data/fetch.sh downloads it (npm package
# `bunny`); this script runs fetch.sh when the file is missing.
#
# Any change to the format's stream bytes or decoding rules bumps the format
# version (decoder-core/SPEC.md §1, decoder-core/src/limits.rs) and
# SUITE_VERSION in conformance/src/manifest.rs, and the new set is generated
# into its own directory; old sets stay as they were. A change to what the
# encoder writes keeps the version: rerun this script and commit the result
# (the regeneration test fails until then).
set -euo pipefail

here="$(cd "$(dirname "${BASH_SOURCE[0]}")" && pwd)"
root="$(cd "$here/.." && pwd)"
cd "$root"

if [[ ! -s encoder/data/real/bunny.ply ]]; then
    echo "generate.sh: encoder/data/real/bunny.ply missing; running encoder/data/fetch.sh" >&2
    bash encoder/data/fetch.sh
fi

cargo run --quiet -p splitstream-conformance --bin splitstream-conformance -- \
    generate --real-data encoder/data/real "$@"
