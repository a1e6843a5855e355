#!/usr/bin/env bash
# DESIGN §2 rule 1: the pure libraries (<component>/include and <component>/src) never include
# DDS, OpenGL/EGL/GLFW or yaml-cpp headers. Only node/ folders, idl/ (the wire layer), runtime/
# (the service runtime) and core/yaml/ (the YAML adapter) may.
set -euo pipefail
root=${1:-.}
cd "$root"
pattern='#[[:space:]]*include[[:space:]]*[<"](dds/|ddsc/|yaml-cpp/|GL/|GLES[0-9]*/|EGL/|GLFW/|epoxy/|glad/)'
hits=$(find . -path ./idl -prune -o -path ./runtime -prune -o -path ./build -prune -o \
            \( -path '*/include/*' -o -path '*/src/*' \) -type f \( -name '*.h' -o -name '*.cc' \) -print \
       | grep -v '/node/' | xargs -r grep -nE "$pattern" || true)
if [ -n "$hits" ]; then
  echo "pure libraries include middleware/GL/YAML headers (DESIGN §2 rule 1):"
  echo "$hits"
  exit 1
fi
echo "pure libraries are clean"
