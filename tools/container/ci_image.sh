#!/usr/bin/env bash
# CI test of the container recipe (Dockerfile; docs/SHARDING.md, "Kubernetes Indexed Job"), run
# for real with podman on a machine that reaches the Debian mirror and crates.io but no container
# registry:
#   1. the Dockerfile's base images are stood in for by local ones: `debootstrap` makes Debian
#      bookworm (minbase) for BASE, and RUST is that plus gcc, with this machine's Rust toolchain
#      mounted read-only at build time (no registry serves rust:1.89-bookworm here);
#   2. both targets are built unchanged from the Dockerfile: `cpu` (default) and `vulkan`;
#   3. the Indexed Job is played by containers of the cpu image as pods: 2 shards with
#      JOB_COMPLETION_INDEX 0 and 1 on a results volume owned by uid 10001 (the Job's fsGroup),
#      then the merge container; the merge must be byte-identical to one container's
#      one-machine run, and its tables equal to this machine's own binary's;
#   4. the vulkan image runs a campaign with --backend gpu on Mesa's lavapipe inside the
#      container, and its tables equal this machine's GPU run of the same campaign.
# Runs as root. Usage: tools/container/ci_image.sh PATH_TO_CRYOSLOSH_BINARY
#
# This VM's limits shape the podman flags: root lacks CAP_SYS_RESOURCE, so the container's
# nofile/nproc limits are set below the current ones (podman's defaults would raise them); the
# cgroup hierarchy is hybrid (v1 + v2 controllers), which crun refuses and runc accepts; RUN steps
# use chroot isolation (no OCI runtime, the host's network).
set -euo pipefail
cd "$(dirname "$0")/../.."
BIN=$(readlink -f "$1")
WORK=$(mktemp -d /tmp/cryoslosh-image.XXXXXX)
TAG=localhost/cryoslosh-ci
# The work directory and the images (several GB in podman's vfs storage) go on any exit.
cleanup() {
    rm -rf "$WORK"
    podman rmi -f "$TAG/cryoslosh:cpu" "$TAG/cryoslosh:vulkan" "$TAG/rust:host" \
        "$TAG/debian:bookworm-slim" >/dev/null 2>&1 || true
    podman image prune -f >/dev/null 2>&1 || true   # the untagged build stages
}
trap cleanup EXIT
fail() {
    echo "container test: $*" >&2
    exit 1
}

DEBIAN_FRONTEND=noninteractive apt-get install -y -qq podman runc debootstrap >/dev/null \
    || fail "cannot install podman, runc and debootstrap with apt-get"

LIMITS=(--ulimit nofile=4096:4096 --ulimit nproc=4096:4096)
RUN=(podman run --rm --runtime runc "${LIMITS[@]}")
MIRROR=${DEBIAN_MIRROR:-http://deb.debian.org/debian}

# 1. Base images. minbase is what debian:bookworm-slim holds (apt, passwd for useradd).
debootstrap --variant=minbase bookworm "$WORK/rootfs" "$MIRROR" >"$WORK/debootstrap.log" 2>&1 \
    || { tail -n 20 "$WORK/debootstrap.log" >&2; fail "debootstrap of bookworm from $MIRROR failed"; }
tar -C "$WORK/rootfs" -c . | podman import --quiet - "$TAG/debian:bookworm-slim" >/dev/null \
    || fail "podman import of the bootstrapped root failed"
rm -rf "$WORK/rootfs"
SYSROOT=$(rustc --print sysroot)
[ -x "$SYSROOT/bin/cargo" ] || fail "no cargo in the toolchain at $SYSROOT"
CARGO_REGISTRY="${CARGO_HOME:-$HOME/.cargo}/registry"
mkdir -p "$CARGO_REGISTRY"
podman build --quiet --isolation chroot "${LIMITS[@]}" \
    --build-arg BASE="$TAG/debian:bookworm-slim" -t "$TAG/rust:host" \
    -f tools/container/rust-host.Containerfile tools/container >"$WORK/build-rust.log" 2>&1 \
    || { tail -n 30 "$WORK/build-rust.log" >&2; fail "the stand-in Rust image does not build"; }
echo "container test: base images ready (debian bookworm minbase; rust $(rustc --version | cut -d' ' -f2) mounted from $SYSROOT)"

# 2. The Dockerfile, both targets. The crate cache is shared with this machine's builds.
BUILD=(podman build --isolation chroot "${LIMITS[@]}"
    -v "$SYSROOT:/usr/local/rust:ro" -v "$CARGO_REGISTRY:/usr/local/cargo/registry"
    --build-arg RUST="$TAG/rust:host" --build-arg BASE="$TAG/debian:bookworm-slim")
"${BUILD[@]}" -t "$TAG/cryoslosh:cpu" . >"$WORK/build-cpu.log" 2>&1 \
    || { tail -n 30 "$WORK/build-cpu.log" >&2; fail "the Dockerfile's cpu target does not build"; }
"${BUILD[@]}" --target vulkan -t "$TAG/cryoslosh:vulkan" . >"$WORK/build-vulkan.log" 2>&1 \
    || { tail -n 30 "$WORK/build-vulkan.log" >&2; fail "the Dockerfile's vulkan target does not build"; }
echo "container test: images built: $(podman images --format '{{.Repository}}:{{.Tag}} {{.Size}}' | grep "$TAG/cryoslosh" | tr '\n' ' ')"
[ "$("${RUN[@]}" "$TAG/cryoslosh:cpu" id -u)" = 10001 ] || fail "the image does not run as uid 10001"

# 3. The Indexed Job: two pods, then the merge pod, on a volume writable by the image's user.
mkdir -p "$WORK/results" "$WORK/campaigns"
cp campaigns/mhtb_selfpress.toml "$WORK/campaigns/"
chown 10001 "$WORK/results"
VOLUMES=(-v "$WORK/results:/results" -v "$WORK/campaigns:/campaigns:ro")
for i in 0 1; do
    "${RUN[@]}" "${VOLUMES[@]}" -e JOB_COMPLETION_INDEX=$i "$TAG/cryoslosh:cpu" /bin/sh -c \
        'cryoslosh run /campaigns/mhtb_selfpress.toml --instances 200 --seed 42 --threads 2 --backend cpu --shard ${JOB_COMPLETION_INDEX}/2 --out /results/shard-${JOB_COMPLETION_INDEX}' \
        >"$WORK/pod-$i.log" 2>&1 || { cat "$WORK/pod-$i.log" >&2; fail "pod $i failed"; }
done
"${RUN[@]}" "${VOLUMES[@]}" "$TAG/cryoslosh:cpu" /bin/sh -c \
    'cryoslosh merge /results/shard-* --out /results/merged && cryoslosh run /campaigns/mhtb_selfpress.toml --instances 200 --seed 42 --threads 2 --backend cpu --out /results/one' \
    >"$WORK/merge.log" 2>&1 || { cat "$WORK/merge.log" >&2; fail "the merge pod failed"; }
for f in instances.parquet statistics.parquet; do
    cmp "$WORK/results/merged/$f" "$WORK/results/one/$f" || fail "merged $f differs from the one-pod run"
done
# This machine's binary on the same campaign: the same tables (the files differ only in the
# campaign path written into their metadata).
"$BIN" run "$WORK/campaigns/mhtb_selfpress.toml" --instances 200 --seed 42 --threads 2 \
    --backend cpu --out "$WORK/host-cpu" >/dev/null
python3 tools/container/same_tables.py "$WORK/results/merged" "$WORK/host-cpu" \
    || fail "the image's results differ from this machine's binary"
echo "container test: Indexed Job (2 pods + merge) byte-identical to one pod, tables equal to the host binary's"

# 4. The vulkan image on lavapipe, against this machine's GPU run (lox_ascent: minutes of
# flight). lavapipe compiles the WGSL kernels with LLVM for minutes on first use; the host's run
# comes first and fills Mesa's shader cache, which the container gets a copy of (the same Mesa
# package: the cache keys match), as a GPU pod would get a persistent MESA_SHADER_CACHE_DIR.
cp campaigns/lox_ascent.toml "$WORK/campaigns/"
XDG_RUNTIME_DIR=${XDG_RUNTIME_DIR:-/tmp} "$BIN" run "$WORK/campaigns/lox_ascent.toml" \
    --instances 64 --seed 7 --backend gpu --out "$WORK/host-gpu" >/dev/null
# (Mesa keeps its cache in MESA_SHADER_CACHE_DIR/mesa_shader_cache.)
CACHE="${XDG_CACHE_HOME:-$HOME/.cache}/mesa_shader_cache"
mkdir -p "$WORK/mesa/mesa_shader_cache"
if [ -d "$CACHE" ]; then cp -r "$CACHE/." "$WORK/mesa/mesa_shader_cache/"; fi
chown -R 10001 "$WORK/mesa"
"${RUN[@]}" "${VOLUMES[@]}" -v "$WORK/mesa:/mesa" -e MESA_SHADER_CACHE_DIR=/mesa \
    -e XDG_RUNTIME_DIR=/tmp "$TAG/cryoslosh:vulkan" \
    cryoslosh run /campaigns/lox_ascent.toml --instances 64 --seed 7 --backend gpu --out /results/gpu \
    >"$WORK/gpu.log" 2>&1 || { cat "$WORK/gpu.log" >&2; fail "the vulkan image's GPU run failed"; }
grep -q '"backend": *"gpu"' "$WORK/results/gpu/run.json" || fail "the vulkan image did not run on the GPU backend"
python3 tools/container/same_tables.py "$WORK/results/gpu" "$WORK/host-gpu" \
    || fail "the vulkan image's GPU results differ from this machine's GPU run"
echo "container test: vulkan image ran --backend gpu on lavapipe, tables equal to this machine's GPU run"
