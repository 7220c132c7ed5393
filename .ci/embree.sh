#!/usr/bin/env bash
# Installs Embree 3 (Debian's libembree3-3, 3.13.5), which blendsynth loads at run time
# for BLENDSYNTH_ACCEL=embree (src/foundation/embree.rs). Nothing is built against it:
# the default build needs no Embree. tests/accel.rs requires it when CI=true, so run this
# before `cargo test`. Takes seconds.
set -euo pipefail
if ldconfig -p | grep -q 'libembree3\.so\.3 '; then
  echo "embree.sh: libembree3.so.3 already installed"
  exit 0
fi
export DEBIAN_FRONTEND=noninteractive
apt-get update -qq
apt-get install -y -qq --no-install-recommends libembree3-3 >/dev/null
ldconfig -p | grep 'libembree3\.so\.3 '
