#!/usr/bin/env bash
# The main job: install, build (Release) and run the showcase scene into out/.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh build
./build/app/aortasph run scenes/aortic_root.json --out out/aortic_root "$@"
