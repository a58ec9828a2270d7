#!/usr/bin/env bash
# Installs the peers that bench/compare.py measures Obscura against. Run by hand, as root
# (Debian bookworm): bash bench/setup.sh. Nothing in the test suite needs any of this.
#   - embreex: Intel Embree 4 behind a Python (Cython) binding, one ray per call;
#   - mitsuba + drjit: Mitsuba 3 from PyPI (scalar_rgb works anywhere; llvm_ad_rgb needs a
#     libLLVM >= 15 on the loader path, and LLVM 15 itself crashes it, so we install 19);
#   - numpy, matplotlib: the harness's arrays and the scaling plot.
set -euo pipefail
if command -v apt-get >/dev/null; then
    apt-get update -qq
    apt-get install -y -qq libllvm19 linux-perf >/dev/null || apt-get install -y -qq libllvm19
fi
python3 -m pip install --quiet --upgrade embreex mitsuba numpy matplotlib
# drjit looks for libLLVM.so; Debian names it libLLVM-19.so.1 / libLLVM.so.19.1.
llvm="$(ls /usr/lib/*/libLLVM.so.19* /usr/lib/*/libLLVM-19.so* 2>/dev/null | head -n 1 || true)"
if [ -n "$llvm" ]; then
    echo "export DRJIT_LIBLLVM_PATH=$llvm   # for mitsuba's llvm_ad_rgb"
fi
python3 - <<'PY'
import embreex, mitsuba
print("embreex", getattr(embreex, "__version__", "?"), "mitsuba", mitsuba.__version__)
PY
