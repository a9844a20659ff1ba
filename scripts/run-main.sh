#!/usr/bin/env bash
# The main job: install, build (Release) and run the showcase scene into out/: the aortic root with shell
# leaflets at their true thickness (issue 16; scenes/aortic_root_shell.json). The paper's volumetric leaflets
# stay in scenes/aortic_root.json (./build/aortasph run scenes/aortic_root.json -> out/aortic_root/).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh build
./build/app/aortasph run scenes/aortic_root_shell.json --out out/aortic_root_shell "$@"
