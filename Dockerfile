# weft for headless work (`weft sweep`, `compare`, `render`) on clusters:
# lavapipe by default, a GPU's Vulkan driver where the runtime provides one.
# Build:  docker build -t weft .
# Run:    docker run --rm -v "$PWD/../shared:/weft/shared:ro" -v /scratch:/out weft \
#             sweep scenes/demo.scene --param shadows.resolution=512,1024 --out /out/sweep
# docs/compare.md ("Many machines") has the Slurm and Kubernetes recipes.
# Without a registry (only Debian's mirrors reachable), build the two base
# images from Debian with tools/container_bases.sh and name them:
#   podman build --build-arg RUST_IMAGE=localhost/weft-rust:bookworm \
#       --build-arg RUNTIME_IMAGE=localhost/weft-debian:bookworm -t weft .

ARG RUST_IMAGE=rust:1-bookworm
ARG RUNTIME_IMAGE=debian:bookworm-slim

FROM ${RUST_IMAGE} AS build
# The build's own packages: the Vulkan loader's headers and the static
# shaderc the gpu crate links (tools/setup's list, less the test tools).
RUN apt-get update \
    && apt-get install -y --no-install-recommends libvulkan-dev libshaderc-dev glslang-dev spirv-tools \
    && rm -rf /var/lib/apt/lists/*
WORKDIR /weft/repo
COPY . .
RUN cargo build --release --locked -p weft-cli

FROM ${RUNTIME_IMAGE}
# The Vulkan loader and Mesa's drivers (lavapipe among them); nothing else
# is loaded at run time (the binary links shaderc statically).
RUN apt-get update \
    && apt-get install -y --no-install-recommends libvulkan1 mesa-vulkan-drivers \
    && rm -rf /var/lib/apt/lists/*
COPY --from=build /weft/repo/target/release/weft /usr/local/bin/weft
# Graphs name shaders relative to themselves and the shipped scenes name
# assets in ../../shared: the same tree as a checkout, shared/ mounted beside it.
COPY graphs /weft/repo/graphs
COPY shaders /weft/repo/shaders
COPY scenes /weft/repo/scenes
WORKDIR /weft/repo
# References are cached here; point it at a shared volume so shards share them.
ENV WEFT_CACHE_DIR=/weft/cache
ENTRYPOINT ["weft"]
