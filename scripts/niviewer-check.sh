#!/bin/sh
# Opens relight's virtual OpenNI2 device in NiViewer2, an OpenNI2 client relight did not write, under
# Xvfb, and saves a screenshot. Optional manual check; needs the Debian packages openni2-utils, xvfb,
# x11-apps and imagemagick (not in scripts/debian-packages.txt). NiViewer2 loads the system
# libOpenNI2, so LD_LIBRARY_PATH points it at relight's redist/ folder, whose drivers include ours.
# Usage: scripts/niviewer-check.sh [BUILD_DIR] [URI] [OUT.png]
set -eu
build=${1:-build/debug}
uri=${2:-relight://synthetic?loop=20}
out=${3:-niviewer.png}
display=:97
Xvfb "$display" -screen 0 1280x1024x24 >/dev/null 2>&1 &
xvfb=$!
trap 'kill "$xvfb" 2>/dev/null || true' EXIT
sleep 1
DISPLAY=$display LD_LIBRARY_PATH="$build/redist" timeout 30 NiViewer2 "$uri" >/dev/null 2>&1 &
viewer=$!
sleep 15  # the first pass of the loop is rendered, later ones stream at 30 fps
DISPLAY=$display xwd -root -silent | convert xwd:- "$out"
kill "$viewer" 2>/dev/null || true
echo "NiViewer2 screenshot of $uri: $out"
