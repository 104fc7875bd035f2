#!/usr/bin/env bash
# Purpose: no plugin reaches into another plugin's folder: a file under plugins/<kind>/<name>/ includes only its own files, plugins/lib (rooted there, never by ../) or the test fixture, and the check proves itself on planted bad includes.
# Usage: plugin_includes.sh <trackflow cli> <plugin dir> <data dir> <repo root> (only the root is used).
set -u
ROOT=$4
source "$(dirname "$0")/lib.sh"

# violations <repo root>: one "file:line: text" per include (or CMake path) of a plugin that leaves
# its folder other than through plugins/lib, files named relative to the root. Quoted includes are
# resolved the way the compiler would for a plugin: next to the including file, then through the
# include directories a plugin may have, plugins/lib (the shared code) and tests/support (the
# plugin test fixture). A quoted include found only elsewhere (an include directory pointing
# into another plugin) or nowhere is reported too. Files in plugins/lib may include only lib.
violations() {
  local root=$1 file rel dir home line text inc target
  while IFS= read -r file; do
    rel=${file#"$root"/}
    dir=$(dirname "$file")
    case "$rel" in
      plugins/lib/*) home="$root/plugins/lib" ;;
      *) home=$(cut -d/ -f1-3 <<<"$rel"); home="$root/$home" ;;
    esac
    while IFS=: read -r line text; do
      inc=$(sed -E 's/^[[:space:]]*#[[:space:]]*include[[:space:]]*"([^"]*)".*/\1/' <<<"$text")
      target=$(realpath -m "$dir/$inc")
      if [ -e "$target" ]; then
        case "$target" in "$home"/*) continue ;; esac
      elif [[ "$inc" != .* ]] && [ -e "$root/plugins/lib/$inc" ]; then
        continue
      elif [[ "$inc" != .* ]] && [ -e "$root/tests/support/$inc" ]; then
        continue
      fi
      echo "$rel:$line: $text"
    done < <(grep -nE '^[[:space:]]*#[[:space:]]*include[[:space:]]*"' "$file")
  done < <(find "$root/plugins" -mindepth 3 -type f \( -name '*.cpp' -o -name '*.hpp' -o -name '*.h' -o -name '*.cc' \) | sort)
  # A plugin's CMakeLists.txt that names a path outside its folder (a source or include directory
  # of another plugin) compiles that plugin's files into this one.
  while IFS= read -r file; do
    rel=${file#"$root"/}
    grep -nE '\.\./' "$file" | sed "s|^|$rel:|;s|^\([^:]*:[0-9]*\):|\1: |"
  done < <(find "$root/plugins" -mindepth 3 -maxdepth 3 -name CMakeLists.txt -not -path "$root/plugins/lib/*" | sort)
}

# The tree itself.
found=$(violations "$ROOT")
if [ -n "$found" ]; then
  printf '%s\n' "$found" >&2
  fail "$(wc -l <<<"$found") line(s) reach outside their plugin's folder (include shared code as \"<part>/<file>\" from plugins/lib, linking its tf_lib_* target)"
fi
echo "ok: every plugin includes only its own files, plugins/lib and the test fixture"
checks=$((checks + 1))

# The same check on a copy with bad includes planted in one plugin: each must be reported at its
# file:line, and a good include next to them must not be, so the pass above is not vacuous.
copy="$TMP/repo"
mkdir -p "$copy/tests"
cp -r "$ROOT/plugins" "$copy/plugins"
cp -r "$ROOT/tests/support" "$copy/tests/support"
victim=$(cd "$copy" && find plugins -mindepth 3 -maxdepth 3 -name '*.cpp' -not -path 'plugins/lib/*' | sort | head -n 1)
[ -n "$victim" ] || fail "no plugin source found to plant includes in"
# A header of a second plugin whose name is unique, so that only its own folder has it.
other=""
while IFS= read -r h; do
  b=$(basename "$h")
  if [ "$(find "$copy/plugins" "$copy/tests/support" -name "$b" | wc -l)" -eq 1 ]; then other=$h; break; fi
done < <(cd "$copy" && find plugins -mindepth 3 -maxdepth 3 -name '*.hpp' -not -path 'plugins/lib/*' \
  -not -path "$(dirname "$victim")/*" | sort)
[ -n "$other" ] || fail "no uniquely named header of a second plugin found to include"
lib_header=$(cd "$copy/plugins/lib" && find . -mindepth 2 -name '*.hpp' | sort | head -n 1 | sed 's|^\./||')
[ -n "$lib_header" ] || fail "plugins/lib has no header"
n=$(wc -l <"$copy/$victim")
{
  echo "#include \"../../${other#plugins/}\""      # another plugin, by a relative path
  echo "#include \"$(basename "$other")\""           # another plugin, through an include directory
  echo "#include \"../../lib/$lib_header\""         # plugins/lib, but not rooted at it
  echo "#include \"$lib_header\""                   # the allowed form
} >>"$copy/$victim"
victim_cmake="$(dirname "$victim")/CMakeLists.txt"
[ -f "$copy/$victim_cmake" ] || fail "$victim_cmake not found"
m=$(wc -l <"$copy/$victim_cmake")
echo "target_include_directories(dummy PRIVATE \${CMAKE_CURRENT_SOURCE_DIR}/../../${other#plugins/})" >>"$copy/$victim_cmake"
planted=$(violations "$copy")
expected=$(printf '%s\n' "$victim:$((n + 1)):" "$victim:$((n + 2)):" "$victim:$((n + 3)):" "$victim_cmake:$((m + 1)):")
got=$(cut -d' ' -f1 <<<"$planted")
if [ "$got" != "$expected" ]; then
  printf 'reported:\n%s\nexpected (file:line):\n%s\n' "$planted" "$expected" >&2
  fail "the check does not report exactly the planted bad includes"
fi
echo "ok: the planted bad includes are reported at their file:line, the rooted lib include is not"
checks=$((checks + 1))
finish
