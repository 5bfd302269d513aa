#!/usr/bin/env bash
# cmake --install puts mupm, its library and headers, its CMake package, the Python tools and the
# example inputs under a prefix; a project outside mupm (tests/install) finds it with
# find_package(mupm), links mupm::mupm and reads the installed quick-start input with it (the
# same point count as the installed mupm's run of that input); the installed mupm --version
# names the revision the library was built from.
#   install.sh MUPM SRC WORK PYTHON MPIEXEC
source "$(dirname "$0")/common.sh"
BUILD=$(cd "$(dirname "$MUPM")" && pwd)
cmake --install "$BUILD" --prefix "$WORK/prefix" >install.log || fail "cmake --install failed (install.log)"
for f in bin/mupm lib/libmupm.a include/mupm/solvers/simulation.hpp include/mupm/core/version.hpp \
  lib/cmake/mupm/mupmConfig.cmake lib/cmake/mupm/mupmConfigVersion.cmake \
  lib/cmake/mupm/mupmTargets.cmake share/mupm/python/mupm_plot.py \
  share/mupm/python/mupm_compare.py share/mupm/python/mupm_kgd.py share/mupm/inputs/quickstart.xml share/mupm/inputs/README.md; do
  [[ -e prefix/$f ]] || fail "cmake --install did not put $f under the prefix"
done
[[ -x prefix/share/mupm/python/mupm_plot.py ]] || fail "mupm_plot.py is not executable"
cmake -S "$SRC/tests/install" -B consumer -DCMAKE_PREFIX_PATH="$WORK/prefix" \
  -DCMAKE_BUILD_TYPE=Release >configure.log 2>&1 || { cat configure.log; fail "the consumer's find_package(mupm) failed"; }
cmake --build consumer -j2 >build.log 2>&1 || { tail -30 build.log; fail "the consumer did not build against mupm::mupm"; }
# The installed mupm, one step of the installed quick start.
MUPM=$WORK/prefix/bin/mupm
sed -e 's|<Parameter name="Number of Steps" type="int" value="[0-9]*"/>|<Parameter name="Number of Steps" type="int" value="1"/>|' \
  -e "s|<Parameter name=\"Folder\" type=\"string\" value=\"[^\"]*\"/>|<Parameter name=\"Folder\" type=\"string\" value=\"$WORK/run\"/>|" \
  prefix/share/mupm/inputs/quickstart.xml >one_step.xml
run 1 1 one_step.xml >run.out 2>&1 || { cat run.out; fail "the installed mupm did not run the quick start"; }
ran=$(sed -nE 's/^mupm: 2D, ([0-9]+) points.*/\1/p' run.out)
[[ -n $ran ]] || { cat run.out; fail "no point count in the installed mupm's output"; }
read=$(timeout 120 "$MPIEXEC" --allow-run-as-root -np 1 consumer/consumer prefix/share/mupm/inputs/quickstart.xml) ||
  fail "the consumer failed: $read"
echo "install: consumer says: $read; the installed mupm ran $ran points"
[[ $read == *": $ran points" ]] || fail "the consumer read '$read', the installed mupm ran $ran points"
version=$("$MUPM" --version)
echo "$version"
revision=$(git -C "$SRC" describe --always --dirty --abbrev=10 2>/dev/null || echo unknown)
[[ $version == "mupm "*" (git $revision)"* ]] || fail "mupm --version says '${version%%$'\n'*}', the source is at $revision"
[[ $read == *"(git $revision)"* ]] || fail "the installed library names another revision: $read"
[[ $version == *"Kokkos "*"execution space OpenMP"* && $version == *"Trilinos 13"* ]] ||
  fail "mupm --version does not name the Kokkos/Trilinos configuration"
echo "install: passed"
