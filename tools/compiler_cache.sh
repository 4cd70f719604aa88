# Sourced by the build scripts (tools/test.sh, tools/fuzz.sh, tools/package.sh), with $root set: compiles through
# ccache when it is installed (tools/install-deps.sh installs it), so that a second run of the test command, in
# this checkout or a fresh clone in another folder, recompiles only what changed. Paths below the tree are hashed
# relative to it (CCACHE_BASEDIR) and the build folder is left out of the hash (CCACHE_NOHASHDIR), which is what
# lets a clone elsewhere hit the cache. Sets `launcher`, the CMake arguments to pass.
launcher=()
if command -v ccache > /dev/null; then
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
  export CCACHE_BASEDIR=${CCACHE_BASEDIR:-$root} CCACHE_NOHASHDIR=${CCACHE_NOHASHDIR:-1}
fi
