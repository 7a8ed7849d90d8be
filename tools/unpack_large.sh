#!/bin/sh
# Unpacks the large scenes the ladder and the denoiser are measured on
# (docs/ladder.md) from
# the shared assets into out/large/, where scenes/large/*.scene read them;
# they stay out of the repository. Run from the repository root.
set -eu
assets="${WEFT_ASSETS:-../shared/assets}"
mkdir -p out/large
unzip -o -q "$assets/large/mcguire/Sibenik_Cathedral/sibenik.zip" -d out/large/sibenik
echo "unpacked out/large/sibenik"
unzip -o -q "$assets/large/mcguire/Dabrovic_Sponza/sponza.zip" -d out/large/sponza
echo "unpacked out/large/sponza"
