#!/usr/bin/env bash
# scripts/bench-bundle.sh [-b BINARY] OUT.tar.xz
#
# Packs relight-bench and the relight CLI beside it (when built), the shared libraries they load
# and data/ into one archive that runs on another x86-64 Linux machine without relight's Debian
# packages (a lent GPU machine, say):
#   tar xJf OUT.tar.xz && relight-bench-bundle/run.sh [relight-bench arguments]
#   relight-bench-bundle/relight.sh replay ...   (e.g. under a profiler, with report.json)
#
# Why stubs: the Debian OpenCV the benchmark links pulls in GDAL, DICOM, FFmpeg, GStreamer and
# SDL through imgcodecs, videoio and the live view (over 300 MB in 280 libraries), none of which a
# benchmark calls. Those libraries are replaced by stubs with the same soname and exported
# symbols (every Debian library here is linked with BIND_NOW, so each symbol must resolve at
# load time); a stub's function prints which library was stubbed and aborts, so a run that does
# need one fails loudly instead of misbehaving (GDAL's return zero: see `silent`). The glibc family is the target's own; libstdc++
# and libgcc_s are the target's own when they are at least as new as this machine's (run.sh
# checks), else the bundled ones.
#
# Default binary: build/release/bench/relight-bench if it exists, else build/debug's (stripped of
# its debug information in the bundle either way); the CLI is ../app/relight from the bench's folder.
set -euo pipefail

root="$(cd "$(dirname "$0")/.." && pwd)"
binary=""
while getopts "b:h" option; do
  case "$option" in
    b) binary="$OPTARG" ;;
    h) sed -n '2,18p' "$0" | sed 's/^# \{0,1\}//'; exit 0 ;;
    *) echo "usage: $0 [-b BINARY] OUT.tar.xz" >&2; exit 2 ;;
  esac
done
shift $((OPTIND - 1))
if [[ $# -ne 1 ]]; then
  echo "usage: $0 [-b BINARY] OUT.tar.xz" >&2
  exit 2
fi
out="$(realpath -m "$1")"
if [[ -z "$binary" ]]; then
  for candidate in "$root/build/release/bench/relight-bench" "$root/build/debug/bench/relight-bench"; do
    if [[ -x "$candidate" ]]; then binary="$candidate"; break; fi
  done
fi
if [[ -z "$binary" || ! -x "$binary" ]]; then
  echo "bench-bundle: no relight-bench binary (build it first, or name one with -b)" >&2
  exit 1
fi

# Libraries the benchmark never calls (see above), by soname prefix.
stubbed='^lib(gdal|gdcm|openjp2|dc1394|gst|glib-2\.0|gobject-2\.0|avcodec|avformat|avutil|swscale|swresample|gphoto2|SDL2)'
# Stubs whose functions return zero instead of aborting: OpenCV's imgcodecs registers its GDAL
# decoder (GDALAllRegister) when it first reads an image, then never uses it for PNG/EXR.
silent='^libgdal'
# The target's own C library family.
system='^(libc|libm|libdl|librt|libpthread|libresolv|libutil|ld-linux-x86-64)\.so'
fallback='^(libstdc\+\+|libgcc_s)\.so'

work="$(mktemp -d)"
trap 'rm -rf "$work"' EXIT
bundle="$work/relight-bench-bundle"
mkdir -p "$bundle/bin" "$bundle/lib" "$bundle/fallback" "$work/stubs"

binaries=("$binary")
cli="$(dirname "$binary")/../app/relight"
[[ -x "$cli" ]] && binaries+=("$cli")

# soname -> path, as this machine's loader resolves the whole closure.
declare -A path_of
while read -r name _ path _; do
  [[ -n "$path" && "$path" == /* ]] && path_of["$name"]="$path"
done < <(for b in "${binaries[@]}"; do ldd "$b"; done | awk '/=>/ {print $1, $2, $3}')

# One stub library: every exported symbol of the real one, functions abort, objects are zeros of
# the real size, symbol versions kept.
make_stub() {
  local soname="$1" real="$2"
  local asm="$work/stubs/$soname.s" script="$work/stubs/$soname.map" called="$work/stubs/$soname.c"
  local body="jmp relight_stub_called"
  [[ "$soname" =~ $silent ]] && body="xorl %eax, %eax\n  ret"
  printf '#include <stdlib.h>\n#include <unistd.h>\n__attribute__((visibility(\"hidden\"))) void relight_stub_called(void) {\n  static const char m[] = "relight bench bundle: %s was stubbed, but the run called it\\n";\n  (void)!write(2, m, sizeof m - 1);\n  abort();\n}\n' \
    "$soname" >"$called"
  nm -D --defined-only -S "$real" | awk -v asm="$asm" -v script="$script" -v body="$body" '
    BEGIN { print ".section .note.GNU-stack,\"\",@progbits" > asm }
    NF == 3 { size = "8"; type = $2; name = $3 }
    NF == 4 { size = ($2 ~ /^0+$/) ? "8" : "0x" $2; type = $3; name = $4 }
    NF < 3 || type == "A" { next }
    {
      version = ""
      if (index(name, "@@")) { split(name, parts, "@@"); name = parts[1]; version = parts[2] }
      else if (index(name, "@")) next  # an old, non-default version: nothing links against it now
      label = version == "" ? name : "relight_stub_" (++count)
      if (type ~ /[TtWwi]/) {
        print ".text\n.globl " label "\n.type " label ",@function\n" label ":\n  " body > asm
      } else {
        print ".data\n.balign 16\n.globl " label "\n.type " label ",@object\n.size " label "," size "\n" label ":\n  .zero " size > asm
      }
      if (version != "") { print ".symver " label "," name "@@" version > asm; versions[version] = 1 }
    }
    END {
      # The first version node exports everything else; a library without versions needs no script.
      first = 1
      for (v in versions) { print v (first ? " { global: *; };" : " { };") > script; first = 0 }
    }'
  local link=("-Wl,-soname,$soname")
  [[ -s "$script" ]] && link+=("-Wl,--version-script=$script")
  gcc -shared -fPIC -o "$bundle/lib/$soname" "${link[@]}" "$asm" "$called"
}

declare -A seen
queue=("${binaries[@]}")
stubs=0 libs=0
while [[ ${#queue[@]} -gt 0 ]]; do
  current="${queue[0]}"
  queue=("${queue[@]:1}")
  while read -r needed; do
    [[ -n "${seen[$needed]:-}" ]] && continue
    seen["$needed"]=1
    [[ "$needed" =~ $system ]] && continue
    real="${path_of[$needed]:-}"
    if [[ -z "$real" ]]; then
      echo "bench-bundle: $needed (needed by $(basename "$current")) is not found on this machine" >&2
      exit 1
    fi
    if [[ "$needed" =~ $fallback ]]; then
      cp -L "$real" "$bundle/fallback/$needed"
    elif [[ "$needed" =~ $stubbed ]]; then
      make_stub "$needed" "$real"
      stubs=$((stubs + 1))
    else
      cp -L "$real" "$bundle/lib/$needed"
      libs=$((libs + 1))
      queue+=("$real")
    fi
  done < <(readelf -d "$current" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p')
done

for b in "${binaries[@]}"; do objcopy --strip-debug "$b" "$bundle/bin/$(basename "$b")"; done
cp -r "$root/data" "$bundle/data"
# run.sh runs relight-bench, relight.sh the CLI, each with the bundle's libraries and data.
for wrapper in run:relight-bench relight:relight; do
  program="${wrapper#*:}" script="$bundle/${wrapper%%:*}.sh"
  [[ -x "$bundle/bin/$program" ]] || continue
  sed "s/@PROGRAM@/$program/" >"$script" <<'EOF'
#!/bin/sh
# Runs the bundled @PROGRAM@ with its libraries and data (scripts/bench-bundle.sh).
here="$(cd "$(dirname "$0")" && pwd)"
libs="$here/lib"
# The target's libstdc++ when it is at least as new as the one the bundle was built with.
system_cxx="$(ldconfig -p 2>/dev/null | awk '/libstdc\+\+\.so\.6 .*x86-64/ {print $NF; exit}')"
needed_cxx="$(cat "$here/fallback/GLIBCXX")"
if [ -z "$system_cxx" ] || ! grep -q "$needed_cxx" "$system_cxx"; then libs="$libs:$here/fallback"; fi
export LD_LIBRARY_PATH="$libs${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export RELIGHT_DATA="${RELIGHT_DATA:-$here/data}"
exec "$here/bin/@PROGRAM@" "$@"
EOF
  chmod +x "$script"
done
# The newest libstdc++ symbol version the bundle's binaries ask for.
strings "$bundle"/bin/* "$bundle"/lib/*.so* | grep -o '^GLIBCXX_3\.4\.[0-9]*$' | sort -t. -k3 -n | tail -1 \
  >"$bundle/fallback/GLIBCXX"

tar -C "$work" -cf - relight-bench-bundle | xz -T2 -6 >"$out.tmp"
mv "$out.tmp" "$out"
echo "bench-bundle: $out ($(du -h "$out" | cut -f1)): ${binaries[*]##*/}, $libs libraries, $stubs stubs, data/"
