#!/bin/sh
# Runs v4l2-compliance (Debian v4l-utils) against the fake V4L2 device and requires every test
# of the format and streaming sections to pass. Exit 77 (skipped) when the tool is absent.
# Usage: compliance.sh /path/to/libfake_v4l2.so
set -u
lib="$1"
command -v v4l2-compliance >/dev/null 2>&1 || { echo "v4l2-compliance not installed: skipped"; exit 77; }
dev=/dev/video42
out=$(ORTHOFACE_FAKE_V4L2=$dev LD_PRELOAD="$lib" v4l2-compliance -d $dev -s 2>&1 | tr '\t' ' ')
echo "$out" | grep -v "Video Capture: Frame"
section() {  # the "test ..." lines between heading $1 and the next blank line
  echo "$out" | awk -v h="$1" 'index($0, h) == 1 {on = 1; next} on && /^$/ {exit} on && /test /'
}
status=0
for h in "Format ioctls" "Buffer ioctls" "Streaming ioctls"; do
  lines=$(section "$h")
  [ -n "$lines" ] || { echo "FAIL: section '$h' missing"; status=1; continue; }
  if echo "$lines" | grep -v ": OK" | grep -q .; then
    echo "FAIL: section '$h' has failures:"; echo "$lines" | grep -v ": OK"; status=1
  fi
done
for t in "test MMAP (no poll): OK" "test MMAP (select): OK" "test VIDIOC_S_FMT: OK"; do
  echo "$out" | grep -qF "$t" || { echo "FAIL: missing '$t'"; status=1; }
done
echo "$out" | grep -q "Failed: 0" || { echo "FAIL: v4l2-compliance reported failures"; status=1; }
exit $status
