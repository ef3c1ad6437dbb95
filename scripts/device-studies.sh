#!/usr/bin/env bash
# The hypothesis studies (rendersim study all) on a machine with a real GPU,
# for sessions that are lent one (the `device` tool; it has no network, so
# everything travels from here).
#
#   bash scripts/device-studies.sh prepare   # here: build dist/rendersim, fetch the Vulkan loader into .gl/
#   # then, with the device tool: carry ["dist", ".gl"], command:
#   #   bash scripts/device-studies.sh run
#   # and copy $OUT/<adapter>.md into docs/measurements/.
set -euo pipefail
cd "$(dirname "$0")/.."
case "${1:-}" in
  prepare)
    cargo build --profile device --locked --features wgpu --bin rendersim
    mkdir -p dist
    cp target/device/rendersim dist/rendersim
    mkdir -p .gl /tmp/amd64/partial
    o='-oAPT::Architecture=amd64 -oAPT::Architectures=amd64 -oDir::State::Lists=/tmp/amd64'
    # shellcheck disable=SC2086
    apt-get $o update -qq
    # shellcheck disable=SC2086
    (cd .gl && apt-get $o download libvulkan1)
    du -sh dist .gl
    ;;
  run)
    : "${OUT:?run this on the device machine, where OUT is set}"
    for f in .gl/*.deb; do dpkg -x "$f" /; done
    ldconfig
    if [ -e /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ] && ! ls /usr/share/vulkan/icd.d/*.json >/dev/null 2>&1; then
      export VK_DRIVER_FILES=/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json
    fi
    nvidia-smi -L || true
    ./dist/rendersim measure grid:64x64 --json > "$OUT/measure-grid64.json"
    ./dist/rendersim study all --markdown "$OUT/studies.md" --json > "$OUT/studies.json" || status=$?
    head -c 4000 "$OUT/studies.md"
    exit "${status:-0}"
    ;;
  *)
    echo "usage: $0 prepare|run" >&2
    exit 2
    ;;
esac
