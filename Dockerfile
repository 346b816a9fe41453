# Container image of the `cryoslosh` CLI for the Kubernetes Indexed Job of docs/SHARDING.md.
#
#   podman build -t cryoslosh:0.1.0 .                   # CPU image (default, last stage)
#   podman build --target vulkan -t cryoslosh:0.1.0-vulkan .   # + Vulkan loader and Mesa (GPU)
#
# The binary targets x86-64-v3 (AVX2, .cargo/config.toml); for older nodes add
#   --build-arg CPU_RUSTFLAGS="-C target-cpu=x86-64"
# BASE and RUST name the base images, for a registry mirror.
ARG RUST=docker.io/library/rust:1.89-bookworm
ARG BASE=docker.io/library/debian:bookworm-slim

# --- build: the CLI alone (the Python package is not needed in the image) ---
FROM ${RUST} AS build
# Empty keeps .cargo/config.toml's x86-64-v3 (an empty RUSTFLAGS would replace it).
ARG CPU_RUSTFLAGS=""
WORKDIR /src
COPY . .
RUN if [ -n "$CPU_RUSTFLAGS" ]; then export RUSTFLAGS="$CPU_RUSTFLAGS"; fi \
 && cargo build --release --locked -p cryoslosh --bin cryoslosh \
 && install -D target/release/cryoslosh /out/cryoslosh

# --- vulkan: for `--backend gpu` / `auto`. Mesa brings lavapipe (software) and the open
# drivers; on NVIDIA nodes the NVIDIA container toolkit injects the driver and its Vulkan ICD
# (set NVIDIA_DRIVER_CAPABILITIES=compute,graphics so the ICD file is mounted). ---
FROM ${BASE} AS vulkan
RUN apt-get update \
 && DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends libvulkan1 mesa-vulkan-drivers \
 && rm -rf /var/lib/apt/lists/* \
 && useradd --system --uid 10001 --create-home cryoslosh
COPY --from=build /out/cryoslosh /usr/local/bin/cryoslosh
COPY campaigns /opt/cryoslosh/campaigns
USER 10001
WORKDIR /home/cryoslosh
CMD ["cryoslosh", "--help"]

# --- cpu (default): the binary on a slim Debian; the CPU engine needs nothing else. ---
FROM ${BASE} AS cpu
RUN useradd --system --uid 10001 --create-home cryoslosh
COPY --from=build /out/cryoslosh /usr/local/bin/cryoslosh
COPY campaigns /opt/cryoslosh/campaigns
USER 10001
WORKDIR /home/cryoslosh
CMD ["cryoslosh", "--help"]
