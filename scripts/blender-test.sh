#!/bin/bash
# Blender 5 reads the default EXR as docs/output-passes.md says: bpy (Blender as a Python
# module, from PyPI) opens a render in the compositor, finds each documented pass by its name
# and writes it out; each must equal, bit for bit, the channels of the file it came from
# (compared by OpenImageIO's idiff). bpy goes into a cache of its own
# (~/.cache/rest-embree/bpy5, about 1 GB), installed once.
#
#   scripts/blender-test.sh [path/to/rest-embree]    run the test
#   scripts/blender-test.sh --install                only install bpy (make test starts this
#                                                    in the background while it builds)
set -euo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
cache=${REST_EMBREE_CACHE:-$HOME/.cache/rest-embree}
site=$cache/bpy5
mkdir -p "$cache"

# One install at a time (the background one, then the test's wait for it).
install() {
    exec 9>"$cache/bpy5.lock"
    flock 9
    if [ -f "$site/.complete" ]; then return 0; fi
    rm -rf "$site"
    if ! python3 -m pip --version >/dev/null 2>&1; then
        echo "blender-test: installing python3-pip" >&2
        if [ "$(id -u)" = 0 ]; then sudo=(); else sudo=(sudo); fi
        DEBIAN_FRONTEND=noninteractive "${sudo[@]}" apt-get -o DPkg::Lock::Timeout=600 install -y -q python3-pip >/dev/null
    fi
    echo "blender-test: installing bpy 5 (Blender as a Python module) into $site" >&2
    python3 -m pip install -q --disable-pip-version-check --root-user-action=ignore --target "$site" 'bpy>=5,<6' \
        && touch "$site/.complete"
}

if [ "${1:-}" = --install ]; then
    install
    exit
fi

exe=$(realpath "${1:-$root/target/release/rest-embree}")
[ -x "$exe" ] || { echo "blender-test: no binary at $exe (cargo build --release)" >&2; exit 1; }
if ! install; then
    echo "blender-test: FAILED: could not install bpy 5 for $(python3 --version 2>&1)" \
        "(bpy 5 needs Python 3.11 and pip)" >&2
    exit 1
fi

work=$(mktemp -d /tmp/rest-embree-blender.XXXXXX)
trap 'rm -rf "$work"' EXIT

# A moving cube, half the frame background: every pass has hits and misses; two samples so the
# mattes have shares.
w=24 h=16
"$exe" render "$root/scenes/calibration_cube.toml" -o "$work/render.exr" -q \
    --width $w --height $h --samples 2

# Blender's pass name, the channels Blender puts it in, the file's channels.
rows=(
    "Combined R,G,B,A R,G,B,A"
    "Alpha R A"
    "Depth R Z"
    "lookback R lookback.V"
    "doppler R doppler.V"
    "object_id R object_id.V"
    "material_id R material_id.V"
    "primitive_id R primitive_id.V"
    "N R,G,B N.X,N.Y,N.Z"
    "P R,G,B P.X,P.Y,P.Z"
    "Pref R,G,B Pref.X,Pref.Y,Pref.Z"
    "Pcam R,G,B Pcam.X,Pcam.Y,Pcam.Z"
)
for k in Object Material; do
    for r in 00 01 02; do
        c=Crypto$k$r
        rows+=("$c R,G,B,A $c.R,$c.G,$c.B,$c.A")
    done
done
passes=()
for row in "${rows[@]}"; do passes+=("${row%% *}"); done

PYTHONPATH=$site python3 "$root/scripts/blender_passes.py" "$work/render.exr" "$work" $w $h \
    "${passes[@]}" >"$work/blender.log" 2>&1 || { cat "$work/blender.log" >&2; exit 1; }
grep '^blender-test:' "$work/blender.log" >&2

failed=0
for row in "${rows[@]}"; do
    read -r pass theirs ours <<<"$row"
    oiiotool "$work/$pass.exr" --ch "$theirs" -o "$work/a.exr"
    oiiotool "$work/render.exr" --ch "$ours" --chnames "$theirs" -o "$work/b.exr"
    if idiff -q -fail 0 -warn 0 "$work/a.exr" "$work/b.exr" >/dev/null; then
        echo "blender-test: $pass equals the file's $ours" >&2
    else
        echo "blender-test: FAILED: Blender's $pass differs from the file's $ours" >&2
        failed=1
    fi
done

# glTF from Blender: a scene modelled and animated with bpy (scripts/blender_gltf.py), exported
# as .glb, renders as its twin written by hand in TOML (tests/data/blender_twin.toml) on both
# backends: every pixel off a silhouette the same (idiff: at most 1.5% of pixels may differ by
# more than 0.004), and the same coverage (mean alpha) within 3%, so no object goes missing.
PYTHONPATH=$site python3 "$root/scripts/blender_gltf.py" "$work/blender.glb" test \
    >"$work/gltf.log" 2>&1 || { cat "$work/gltf.log" >&2; exit 1; }
cp "$root/tests/data/blender_scene.toml" "$work/scene.toml"
# What the twin takes from the file: the light's candela and the keyed box's first and last
# keys (f32), as the reader computes with them.
read -r light t0 t1 v < <(python3 - "$work/blender.glb" <<'PY'
import json, struct, sys
b = open(sys.argv[1], "rb").read()
n = struct.unpack("<I", b[12:16])[0]
j = json.loads(b[20:20 + n])
bin0 = 20 + n + 8
def floats(a, width):
    acc = j["accessors"][a]
    view = j["bufferViews"][acc["bufferView"]]
    at = bin0 + view.get("byteOffset", 0) + acc.get("byteOffset", 0)
    return struct.unpack(f"<{acc['count'] * width}f", b[at:at + 4 * width * acc["count"]])
cd = j["extensions"]["KHR_lights_punctual"]["lights"][0]["intensity"]
cd = struct.unpack("<f", struct.pack("<f", cd))[0]
s = j["animations"][0]["samplers"][0]
times, xyz = floats(s["input"], 1), floats(s["output"], 3)
t0, t1, x0, x1 = times[0], times[-1], xyz[0], xyz[-3]
print(repr(cd / 683.0), repr(t0 * 10.0), repr(t1 * 10.0), repr((x1 - x0) / ((t1 - t0) * 10.0)))
PY
)
sed -e "s/@LIGHT@/$light/" -e "s/@T0@/$t0/" -e "s/@T1@/$t1/" -e "s/@V@/$v/" \
    "$root/tests/data/blender_twin.toml" >"$work/twin.toml"
# Embree under every instruction set this CPU has (its instances of the linked duplicate's one
# mesh among them), and the f64 BVH.
runs="bvh"
for isa in avx512 avx2 avx sse4.2 sse2; do
    if REST_EMBREE_ISA=$isa "$exe" backends >/dev/null 2>&1; then runs="embree:$isa $runs"; fi
done
cover() { oiiotool "$1" --ch A --printstats | awk '/Stats Avg/ {print $3}'; }
for run in $runs; do
    backend=${run%%:*}
    isa=${run#"$backend"}; isa=${isa#:}
    name="$backend${isa:+ under REST_EMBREE_ISA=$isa}"
    g="$work/gltf-$backend" t="$work/twin-$backend"
    REST_EMBREE_ISA=$isa "$exe" render "$work/scene.toml" -o "$g.png" -q --backend $backend
    REST_EMBREE_ISA=$isa "$exe" render "$work/twin.toml" -o "$t.png" -q --backend $backend
    if idiff -q -fail 0.004 -failpercent 1.5 -hardfail 1 "$g.png" "$t.png" >/dev/null; then
        echo "blender-test: the Blender-made glTF renders as its TOML twin on $name" >&2
    else
        idiff -fail 0.004 -failpercent 1.5 "$g.png" "$t.png" >&2 || true
        echo "blender-test: FAILED: the Blender-made glTF differs from its TOML twin on $name" >&2
        failed=1
    fi
    # What the colour check lets pass (a few percent of pixels) could be an object missing:
    # the two frames' coverage (mean alpha) agree to within 3% of either, silhouettes aside.
    REST_EMBREE_ISA=$isa "$exe" render "$work/scene.toml" -o "$g.exr" -q --backend $backend
    REST_EMBREE_ISA=$isa "$exe" render "$work/twin.toml" -o "$t.exr" -q --backend $backend
    a=$(cover "$g.exr") b=$(cover "$t.exr")
    if python3 -c "import sys; a, b = float(sys.argv[1]), float(sys.argv[2]); sys.exit(not (b > 0 and abs(a - b) <= 0.03 * b))" "$a" "$b"; then
        echo "blender-test: the Blender-made glTF covers what its twin covers on $name ($a of the frame, $b)" >&2
    else
        echo "blender-test: FAILED: the Blender-made glTF covers $a of the frame on $name, its twin $b" >&2
        failed=1
    fi
done
exit $failed
