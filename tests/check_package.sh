#!/usr/bin/env bash
# Checks vkrt's Debian package (tools/package.sh) as a user gets it. Usage (as root, or where unprivileged user
# namespaces may mount overlayfs): tests/check_package.sh <vkrt_*.deb> <pathtracer binary>
#
#   1. Its files (dpkg-deb -c): the driver in the multiarch library folder and the loader's manifest in
#      /usr/share/vulkan/icd.d, owned by root, the library stripped and not executable; nothing else (no tests,
#      examples, GoogleTest or other third-party files).
#   2. Its control fields: name, version, architecture, section, maintainer, description; Depends names libvulkan1
#      and the package of every library the driver links (what dpkg-shlibdeps found), each installed here.
#   3. The manifest in the package: library_path is absolute and is the packaged library's path.
#   4. Installed: the package is unpacked into a scratch root whose folders are laid over the system's real ones
#      (read-only overlayfs: /usr shows the system's /usr plus the package's files) in a private mount namespace.
#      There the Vulkan loader, with no VK_DRIVER_FILES / VK_ICD_FILENAMES and its default search path, must load
#      the packaged manifest and library: vulkaninfo --summary lists vkrt (tests/run_vulkaninfo.sh), and the path
#      tracer renders a small image through it. (The package's maintainer scripts, CPack's ldconfig calls, do not
#      run there: the loader opens the library by its absolute path.)
# Nothing is installed or mounted on the system itself: the mounts exist only in the namespace, which ends with
# its last process, and the scratch folder is removed.
set -euo pipefail
here=$(cd "$(dirname "$0")" && pwd)

fail() { echo "check_package: FAIL: $*" >&2; exit 1; }

# ---- Step 4, inside the private mount namespace (the script runs itself there) ----
if [ "${1:-}" = --in-namespace ]; then
  scratchRoot=$2 manifest=$3 library=$4 pathtracer=$5 out=$6
  for dir in "$scratchRoot"/*; do
    top=/$(basename "$dir")
    [ -d "$top" ] || fail "the package has $top, which this system lacks"
    # Upper layer first: the package's files over the system's.
    mount -t overlay vkrt-package -o "ro,lowerdir=$dir:$top" "$top"
  done
  [ -f "$manifest" ] && [ -f "$library" ] || fail "the overlay does not show $manifest and $library"
  # The loader's defaults only: no driver files named, no other search folders, no driver selection.
  unset VK_DRIVER_FILES VK_ICD_FILENAMES VK_ADD_DRIVER_FILES VK_LOADER_DRIVERS_SELECT VK_LOADER_DRIVERS_DISABLE \
    XDG_DATA_DIRS XDG_CONFIG_DIRS VK_INSTANCE_LAYERS VK_LOADER_LAYERS_ENABLE
  # The loader's own report: which manifest it found and which library it loaded from it.
  log=$(VK_LOADER_DEBUG=driver vulkaninfo --summary 2>&1) || { echo "$log"; fail "vulkaninfo --summary failed"; }
  grep -q "Found ICD manifest file $manifest" <<< "$log" ||
    { echo "$log"; fail "the loader did not find $manifest"; }
  grep -q "Searching for ICD drivers named $library" <<< "$log" ||
    { echo "$log"; fail "the loader did not load $library"; }
  # vulkaninfo as a user runs it: vkrt listed, nothing reported (the same check as the vulkaninfo tests).
  summary=$("$here/run_vulkaninfo.sh" vulkaninfo --summary) || { echo "$summary"; fail "vulkaninfo --summary"; }
  grep -q "driverName *= vkrt" <<< "$summary" || { echo "$summary"; fail "no driverName vkrt"; }
  echo "$summary" | grep -E "deviceName|driverName|driverInfo|deviceType" | sed 's/^ */  vulkaninfo: /'
  # The path tracer (it may be built with AddressSanitizer; the driver is not instrumented, so its allocations
  # at exit are not the program's leaks).
  rm -f "$out"
  ASAN_OPTIONS=${ASAN_OPTIONS:+$ASAN_OPTIONS:}detect_leaks=0 timeout 300 "$pathtracer" --width 32 --height 24 --spp 2 --out "$out" \
    > "$out.log" 2>&1 || { cat "$out.log"; fail "the path tracer failed through the installed package"; }
  python3 - "$out" <<'PY' || { cat "$out.log"; fail "the path tracer's PNG"; }
import struct, sys
data = open(sys.argv[1], "rb").read()
assert data[:8] == b"\x89PNG\r\n\x1a\n" and data[12:16] == b"IHDR", "not a PNG"
w, h = struct.unpack(">II", data[16:24])
assert (w, h) == (32, 24), f"{w}x{h}, not 32x24"
PY
  echo "  path tracer: $(grep -c . "$out.log") lines of output, wrote a 32x24 PNG"
  exit 0
fi

[ $# -eq 2 ] || { echo "usage: tests/check_package.sh <vkrt_*.deb> <pathtracer binary>" >&2; exit 2; }
deb=$(realpath "$1")
pathtracer=$(realpath "$2")
[ -f "$deb" ] || fail "no package $deb"
[ -x "$pathtracer" ] || fail "no path tracer $pathtracer"
multiarch=$(dpkg-architecture -qDEB_HOST_MULTIARCH 2> /dev/null)
arch=$(dpkg --print-architecture)
library=/usr/lib/$multiarch/libvkrt.so
manifest=/usr/share/vulkan/icd.d/vkrt_icd.$(uname -m).json
echo "check_package: $deb"

# ---- 1. Files ----
listing=$(dpkg-deb -c "$deb")
echo "$listing" | sed 's/^/  /'
# Type, owner and path of each entry (dpkg-deb -c: mode owner/group size date time path).
entries=$(echo "$listing" | awk '{ print substr($1, 1, 1), $2, $6 }')
files=$(echo "$entries" | awk '$1 != "d" { print $3 }' | sort)
expected=$(printf '%s\n' ".$library" ".$manifest" | sort)
[ "$files" = "$expected" ] || fail "the package's files are
$files
expected exactly
$expected"
# Every folder is one above those files.
while read -r type owner path; do
  [ "$owner" = root/root ] || fail "$path is owned by $owner"
  [ "$type" = d ] || continue
  case ".$library/ .$manifest/" in *"$path"*) ;; *) fail "unexpected folder $path" ;; esac
done <<< "$entries"
grep -q -- "^-rw-r--r-- .* \.$library$" <<< "$listing" || fail "$library is not a plain 0644 file"
grep -q -- "^-rw-r--r-- .* \.$manifest$" <<< "$listing" || fail "$manifest is not a plain 0644 file"

# ---- 2. Control fields ----
field() { dpkg-deb -f "$deb" "$1"; }
[ "$(field Package)" = vkrt ] || fail "Package is $(field Package)"
[ "$(field Architecture)" = "$arch" ] || fail "Architecture is $(field Architecture), not $arch"
[[ "$(basename "$deb")" == "vkrt_$(field Version)_$arch.deb" ]] || fail "the file name is not vkrt_<version>_$arch.deb"
for f in Version Maintainer Section Description; do [ -n "$(field $f)" ] || fail "no $f"; done
depends=$(field Depends)
echo "  Depends: $depends"
depNames=$(echo "$depends" | tr ',|' '\n\n' | sed 's/(.*)//; s/:any//; s/ //g' | grep .)
grep -qx libvulkan1 <<< "$depNames" || fail "Depends lacks the loader, libvulkan1"
# Each dependency is installed here, at a version that satisfies it.
echo "$depends" | tr ',' '\n' | while read -r dep; do
  alt=${dep%%|*}
  name=$(echo "$alt" | sed 's/(.*//; s/:any//; s/ //g')
  version=$(dpkg-query -W -f='${db:Status-Abbrev} ${Version}' "$name" 2> /dev/null | awk '$1 == "ii" { print $2 }')
  [ -n "$version" ] || fail "dependency $name is not installed here"
  if [[ "$alt" =~ \((..?)\ *([^\)]*)\) ]]; then
    dpkg --compare-versions "$version" "${BASH_REMATCH[1]}" "${BASH_REMATCH[2]}" ||
      fail "$name $version does not satisfy $alt"
  fi
done

scratch=$(mktemp -d /tmp/vkrt-package.XXXXXX)
trap 'rm -rf "$scratch"' EXIT
dpkg-deb -x "$deb" "$scratch/root"
ldconfig=$(command -v ldconfig || echo /sbin/ldconfig)
# The package of each library the driver links is declared (dpkg-shlibdeps ran and found them all).
for soname in $(readelf -d "$scratch/root$library" | sed -n 's/.*(NEEDED).*\[\(.*\)\]/\1/p'); do
  path=$("$ldconfig" -p | awk -v s="$soname" -v d="/$multiarch/" '$1 == s && index($NF, d) { print $NF }' | sed -n 1p)
  [ -n "$path" ] || fail "the driver links $soname, which the dynamic linker does not know"
  # Debian 12 merges /lib into /usr/lib; dpkg knows each file under the path its package ships it.
  owner=$( (dpkg -S "$path" || dpkg -S "${path#/usr}" || dpkg -S "/usr$path") 2> /dev/null | awk -F: 'NR == 1 { print $1 }')
  [ -n "$owner" ] || fail "no package owns $path ($soname)"
  grep -qx "$owner" <<< "$depNames" || fail "the driver links $soname ($owner), which Depends does not name"
done
[ "$(readelf -S "$scratch/root$library" | grep -c '\.symtab')" = 0 ] || fail "$library is not stripped"

# ---- 3. The manifest ----
python3 - "$scratch/root$manifest" "$library" <<'PY' || fail "the packaged manifest"
import json, os, sys
m = json.load(open(sys.argv[1]))
path = m["ICD"]["library_path"]
assert os.path.isabs(path), f"library_path {path} is not absolute"
assert path == sys.argv[2], f"library_path {path} is not the packaged library {sys.argv[2]}"
assert m["file_format_version"] and m["ICD"]["api_version"], "no file_format_version or api_version"
print(f"  manifest: library_path {path}, api_version {m['ICD']['api_version']}")
PY

# ---- 4. Installed, in a private mount namespace ----
unshareArgs=(--mount --propagation private)
[ "$(id -u)" -eq 0 ] || unshareArgs+=(--user --map-root-user)
unshare "${unshareArgs[@]}" -- "$0" --in-namespace "$scratch/root" "$manifest" "$library" "$pathtracer" \
  "$scratch/pt.png" || fail "through the installed package (in a private mount namespace)"
# Nothing stayed mounted (the namespace is gone).
! grep -q vkrt-package /proc/self/mountinfo || fail "an overlay of the package is still mounted"
echo "check_package: OK"
