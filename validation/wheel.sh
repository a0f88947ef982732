#!/usr/bin/env bash
# The Python wheel and the pre-commit hooks that use it, as a robot repository's contributor runs them:
# builds the wheel with maturin (validation/wheel-build-requirements.txt), installs it into a fresh venv
# with pinned pre-commit (validation/wheel-hook-requirements.txt), then, in an environment whose PATH has
# no cargo (checked), runs both hooks of the mirror template (packaging/pre-commit-mirror) with
# `pre-commit try-repo` on a generated robot repository: a URDF and a xacro robot whose macro file has
# a negative mass. pip finds the wheel in a local directory (PIP_FIND_LINKS, PIP_NO_INDEX): no index is
# used while the hooks install. Everything happens in a temporary directory: the tree stays clean.
# Usage: bash validation/wheel.sh
# Environment: WHEEL_DIR=DIR uses the wheel already built in DIR instead of building one;
# WHEEL_KEEP=1 keeps the work directory for a look.
set -euo pipefail
cd "$(dirname "$0")/.."
start=$SECONDS
work="$(mktemp -d -t urdf-inertia-wheel.XXXXXX)"
cleanup() {
  if [ "${WHEEL_KEEP:-0}" = 1 ]; then echo "work directory kept: $work"; else rm -rf "$work"; fi
}
trap cleanup EXIT

fail() {
  echo "error: $*" >&2
  exit 1
}

version="$(sed -n 's/^version = "\(.*\)"$/\1/p' Cargo.toml | head -n 1)"
[ -n "$version" ] || fail "no version in Cargo.toml"
grep -q "\"urdf-inertia==$version\"" packaging/pre-commit-mirror/pyproject.toml ||
  fail "packaging/pre-commit-mirror/pyproject.toml must depend on urdf-inertia==$version (the crate's version)"

# 1. The wheel: one release build (maturin honours CARGO_TARGET_DIR).
wheels="$work/wheels"
mkdir -p "$wheels"
if [ -n "${WHEEL_DIR:-}" ]; then
  cp "$WHEEL_DIR"/urdf_inertia-"$version"-*.whl "$wheels"/
else
  python3 -m venv "$work/build-venv"
  "$work/build-venv/bin/python" -m pip install --quiet --disable-pip-version-check \
    -r validation/wheel-build-requirements.txt
  if ! "$work/build-venv/bin/maturin" build --release --locked --out "$wheels" >"$work/maturin.log" 2>&1; then
    cat "$work/maturin.log"
    fail "maturin build failed"
  fi
fi
shopt -s nullglob
built=("$wheels"/urdf_inertia-"$version"-*.whl)
shopt -u nullglob
[ "${#built[@]}" = 1 ] || fail "expected one urdf_inertia-$version wheel in $wheels, found ${#built[@]}"
wheel="${built[0]}"
echo "== wheel: $(basename "$wheel") ($(du -k "$wheel" | cut -f1) KiB, built in $((SECONDS - start)) s)"

# 2. A fresh venv with the wheel and pre-commit; the mirror's build backend beside the wheel.
venv="$work/venv"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-index "$wheel"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check -r validation/wheel-hook-requirements.txt
"$venv/bin/python" -m pip download --quiet --disable-pip-version-check --no-deps -d "$wheels" \
  -r validation/wheel-mirror-build-requirements.txt

# The contributor's environment: the venv and the system's tools, no cargo, no rustc, no index.
mkdir -p "$work/home"
isolated() {
  env -i HOME="$work/home" PATH="$venv/bin:/usr/bin:/bin" LANG=C.UTF-8 \
    PIP_NO_INDEX=1 PIP_FIND_LINKS="$wheels" PIP_DISABLE_PIP_VERSION_CHECK=1 \
    PRE_COMMIT_HOME="$work/pre-commit-cache" PRE_COMMIT_COLOR=never \
    GIT_CONFIG_NOSYSTEM=1 GIT_AUTHOR_NAME=ci GIT_AUTHOR_EMAIL=ci@localhost \
    GIT_COMMITTER_NAME=ci GIT_COMMITTER_EMAIL=ci@localhost "$@"
}
if isolated sh -c 'command -v cargo || command -v rustc'; then
  fail "cargo or rustc is on the isolated PATH"
fi
isolated sh -c 'command -v git' >/dev/null || fail "pre-commit needs git in /usr/bin or /bin"
[ "$(isolated sh -c 'command -v urdf-inertia')" = "$venv/bin/urdf-inertia" ] ||
  fail "the wheel did not put urdf-inertia on the venv's PATH"
got="$(isolated urdf-inertia --version)"
case "$got" in
  *"$version"*) echo "== $got, from the wheel, cargo not on the PATH" ;;
  *) fail "urdf-inertia --version says '$got', expected $version" ;;
esac

# The two manifests are valid and define the same hooks but for the language.
isolated pre-commit validate-manifest .pre-commit-hooks.yaml packaging/pre-commit-mirror/.pre-commit-hooks.yaml
hooks_of() { sed -n '/^- id:/,$p' "$1" | sed -e 's/^  language: .*$/  language: LANG/'; }
if ! diff -u <(hooks_of .pre-commit-hooks.yaml) <(hooks_of packaging/pre-commit-mirror/.pre-commit-hooks.yaml); then
  fail ".pre-commit-hooks.yaml and packaging/pre-commit-mirror/.pre-commit-hooks.yaml differ beyond the language"
fi

# 3. The mirror template as a repository of its own, as pre-commit clones it.
mirror="$work/mirror"
cp -R packaging/pre-commit-mirror "$mirror"
isolated git -C "$mirror" -c init.defaultBranch=main init --quiet
isolated git -C "$mirror" add -A
isolated git -C "$mirror" commit --quiet -m mirror

# 4. A robot repository: a xacro robot whose macro file has a negative mass, then a URDF with a good
# link and one without an <inertial>. Boxes and cylinders: no meshes needed.
repo="$work/robot"
mkdir -p "$repo/urdf"
isolated git -C "$repo" -c init.defaultBranch=main init --quiet
cat >"$repo/densities.toml" <<'EOF'
default = 1000.0
EOF
# The fill hook has no density arguments: it takes the density map named here, as the README says.
cat >"$repo/urdf-inertia.toml" <<'EOF'
density-map = "densities.toml"
EOF
cat >"$repo/urdf/robot.urdf.xacro" <<'EOF'
<?xml version="1.0"?>
<robot name="two_arms" xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:arg name="with_right_arm" default="true"/>
  <xacro:include filename="arm_macro.xacro"/>
  <link name="base_link">
    <inertial>
      <mass value="6"/>
      <inertia ixx="0.065" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.025"/>
    </inertial>
    <collision>
      <geometry><box size="0.1 0.2 0.3"/></geometry>
    </collision>
  </link>
  <xacro:arm prefix="left_" parent="base_link"/>
  <xacro:if value="$(arg with_right_arm)">
    <xacro:arm prefix="right_" parent="base_link"/>
  </xacro:if>
</robot>
EOF
cat >"$repo/urdf/arm_macro.xacro" <<'EOF'
<?xml version="1.0"?>
<robot xmlns:xacro="http://www.ros.org/wiki/xacro">
  <xacro:macro name="arm" params="prefix parent">
    <link name="${prefix}upper_arm">
      <inertial>
        <mass value="-1.5"/>
        <inertia ixx="0.00655" ixy="0" ixz="0" iyy="0.00655" iyz="0" izz="0.000382"/>
      </inertial>
      <collision>
        <geometry><cylinder radius="0.03" length="0.3"/></geometry>
      </collision>
    </link>
    <joint name="${prefix}shoulder" type="fixed">
      <parent link="${parent}"/>
      <child link="${prefix}upper_arm"/>
    </joint>
  </xacro:macro>
</robot>
EOF
# Diagnostics point at the <inertial> element where it is written in the macro file.
macro_line="$(grep -n '<inertial>' "$repo/urdf/arm_macro.xacro" | head -n 1 | cut -d: -f1)"

# Runs the mirror's hooks (both, in the manifest's order: check, then fill) with try-repo in the robot
# repository; the output goes to $work/hooks.log. try-repo installs the hook environment anew on every
# call (a temporary store), so the script makes two calls.
# Usage: hooks EXPECTED_STATUS [pre-commit args...]
hooks() {
  local expected="$1" status=0
  shift
  (cd "$repo" && isolated pre-commit try-repo "$mirror" "$@") >"$work/hooks.log" 2>&1 || status=$?
  if [ "$status" != "$expected" ]; then
    cat "$work/hooks.log"
    fail "pre-commit try-repo $*: exit $status, expected $expected"
  fi
}
expect_in_log() {
  grep -qF -- "$1" "$work/hooks.log" || {
    cat "$work/hooks.log"
    fail "the hooks' output lacks '$1'"
  }
}

cat >"$repo/urdf/cart.urdf" <<'EOF'
<?xml version="1.0"?>
<robot name="cart">
  <link name="chassis">
    <inertial>
      <mass value="6"/>
      <inertia ixx="0.065" ixy="0" ixz="0" iyy="0.05" iyz="0" izz="0.025"/>
    </inertial>
    <collision>
      <geometry><box size="0.1 0.2 0.3"/></geometry>
    </collision>
  </link>
  <link name="wheel">
    <collision>
      <geometry><cylinder radius="0.05" length="0.02"/></geometry>
    </collision>
  </link>
  <joint name="axle" type="continuous">
    <parent link="chassis"/>
    <child link="wheel"/>
  </joint>
</robot>
EOF
isolated git -C "$repo" add -A
hooks 1
expect_in_log "arm_macro.xacro:$macro_line: link \`left_upper_arm\`"
expect_in_log "mass -1.5 is not positive"
expect_in_log "link \`wheel\`"
expect_in_log "files were modified by this hook"
cp "$work/hooks.log" "$work/hooks-first.log"
echo "== check hook: fails on the negative mass in the macro file and on the wheel without <inertial>:"
grep -E "^urdf/(arm_macro.xacro:$macro_line|cart.urdf:[0-9]+: link \`wheel\`)" "$work/hooks.log" | sed 's/^/   /'
"$venv/bin/python" - "$repo/urdf/cart.urdf" <<'EOF'
import math, sys
import xml.etree.ElementTree as ET

link = next(l for l in ET.parse(sys.argv[1]).getroot().iter("link") if l.get("name") == "wheel")
inertial = link.find("inertial")
assert inertial is not None, "fill wrote no <inertial> for the wheel"
r, h = 0.05, 0.02
m = 1000.0 * math.pi * r * r * h
want = {"ixx": m * (3 * r * r + h * h) / 12, "iyy": m * (3 * r * r + h * h) / 12, "izz": m * r * r / 2}
got_m = float(inertial.find("mass").get("value"))
assert abs(got_m - m) <= 1e-9 * m, (got_m, m)
tensor = inertial.find("inertia")
for key, value in want.items():
    got = float(tensor.get(key))
    assert abs(got - value) <= 1e-9 * value, (key, got, value)
print(f"== fill hook: wrote the wheel's <inertial> (mass {got_m} kg, the cylinder's {m:.10g})")
EOF
isolated git -C "$repo" diff --stat | sed 's/^/   /'

# The fill hook also fixed the macro: its link has nothing computed inside it but its name, so every
# call makes the same link, and fill -i writes the solid cylinder's mass (1000 * pi * 0.03^2 * 0.3 =
# 0.848 kg) into the macro body. Staged with the filled URDF: the whole repository, so this run is
# the one a clean commit gets.
if ! grep -qE '<mass value="0\.848[0-9]*"/>' "$repo/urdf/arm_macro.xacro"; then
  cat "$repo/urdf/arm_macro.xacro"
  fail "the fill hook did not write the cylinder's mass into the arm macro's body"
fi
echo "== fill hook: wrote the arm macro's <inertial> into its body ($(grep -oE '<mass value="[^"]*"/>' "$repo/urdf/arm_macro.xacro"))"
isolated git -C "$repo" add -A
hooks 0
isolated git -C "$repo" commit --quiet -m "two arms and a cart"
echo "== both hooks pass on the fixed files (fill's second run: nothing to write); committed"

# 5. The README's configuration for a xacro repository: a local hook with language: python and the wheel
# as additional dependency; check runs on the top-level files with their --arg and the density map
# whatever robot file changed (pass_filenames: false), so a commit that touches only the macro file is
# checked too.
cat >"$repo/.pre-commit-config.yaml" <<EOF
repos:
  - repo: local
    hooks:
      - id: urdf-inertia-check
        name: urdf-inertia check
        entry: urdf-inertia check
        language: python
        additional_dependencies: [urdf-inertia==$version]
        files: \.(urdf|xacro)$|^densities\.toml$
        pass_filenames: false
        args: [urdf/robot.urdf.xacro, urdf/cart.urdf, --arg, "with_right_arm:=false", --density-map, densities.toml]
EOF
run_config() {
  local expected="$1" status=0
  shift
  (cd "$repo" && isolated pre-commit run "$@") >"$work/hooks.log" 2>&1 || status=$?
  if [ "$status" != "$expected" ]; then
    cat "$work/hooks.log"
    fail "pre-commit run $*: exit $status, expected $expected"
  fi
}
isolated git -C "$repo" add -A
run_config 0 --all-files
isolated git -C "$repo" commit --quiet -m "pre-commit configuration"
sed -i -E 's/<mass value="0\.848[0-9]*"\/>/<mass value="-0.848"\/>/' "$repo/urdf/arm_macro.xacro"
grep -qF '<mass value="-0.848"/>' "$repo/urdf/arm_macro.xacro" || fail "the macro's mass was not broken for the test"
isolated git -C "$repo" add urdf/arm_macro.xacro
run_config 1
expect_in_log "arm_macro.xacro:$macro_line: link \`left_upper_arm\`"
if grep -qF right_upper_arm "$work/hooks.log"; then
  cat "$work/hooks.log"
  fail "--arg with_right_arm:=false was not applied"
fi
echo "== the README's xacro configuration (local, language: python, --arg, --density-map): passes on the"
echo "   clean commit, fails when only the macro file changes:"
grep -F "arm_macro.xacro:$macro_line" "$work/hooks.log" | sed 's/^/   /'
echo "wheel.sh: passed in $((SECONDS - start)) s"
