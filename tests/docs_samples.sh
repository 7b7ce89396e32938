#!/usr/bin/env bash
# The documentation's examples, checked (run by `make examples`, from the
# repository root, after `make stage examples-build`):
#   bash tests/docs_samples.sh [STAGE [EXAMPLES]]   (default build/stage, build/examples)
# Every ```c block of README.md and docs/guide.md is compiled against the
# staged install with pkg-config only and run; what it prints is compared
# with the output block marked after it, and every command block of the
# guide ("$ shear_flow ...") is run with the examples built against the stage
# and compared with what the guide shows. tests/docs_samples.py states the
# rules: markers, tolerances (numbers to 1e-6 relative, text exactly after
# whitespace normalisation), elisions, masked fields.
set -u
stage=${1:-build/stage}
examples=${2:-$(dirname "$stage")/examples}
export OPENBLAS_NUM_THREADS=1
py=$(command -v /usr/bin/python3 || command -v python3) || { echo "docs-samples: no python3"; exit 1; }
exec "$py" "$(dirname "$0")/docs_samples.py" "$stage" "$examples" README.md docs/guide.md
