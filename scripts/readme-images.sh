#!/usr/bin/env bash
# Render the README's pictures (docs/img) from the scenes. Needs a release build.
# Each picture's command is written here in full, as the README shows it under the picture
# (`rest-embree` for "$r", docs/img/ for "$o/"); tests/suite/house.rs holds the two to the same
# commands. Films are shown as six frames joined by oiiotool.
set -euo pipefail
cd "$(dirname "$0")/.."
r=./target/release/rest-embree
o=docs/img
mkdir -p "$o"
q=--quiet
# The first scene of the README.
$r render scenes/first.toml -o "$o/first.png" $q
# The paper's three scenes at four speeds.
$r render scenes/lattice.toml -o "$o/lattice-0.png" --width 320 --height 320 --samples 4 --set 'group.lattice.velocity=[-0, 0, 0]' $q
$r render scenes/lattice.toml -o "$o/lattice-0.5.png" --width 320 --height 320 --samples 4 --set 'group.lattice.velocity=[-0.5, 0, 0]' $q
$r render scenes/lattice.toml -o "$o/lattice-0.9.png" --width 320 --height 320 --samples 4 --set 'group.lattice.velocity=[-0.9, 0, 0]' $q
$r render scenes/lattice.toml -o "$o/lattice-0.99.png" --width 320 --height 320 --samples 4 --set 'group.lattice.velocity=[-0.99, 0, 0]' $q
$r render scenes/bar_array.toml -o "$o/bars-0.png" --width 320 --height 320 --samples 4 --set 'group.bars.velocity=[0, 0, 0]' $q
$r render scenes/bar_array.toml -o "$o/bars-0.5.png" --width 320 --height 320 --samples 4 --set 'group.bars.velocity=[0.5, 0, 0]' $q
$r render scenes/bar_array.toml -o "$o/bars-0.9.png" --width 320 --height 320 --samples 4 --set 'group.bars.velocity=[0.9, 0, 0]' $q
$r render scenes/bar_array.toml -o "$o/bars-0.99.png" --width 320 --height 320 --samples 4 --set 'group.bars.velocity=[0.99, 0, 0]' $q
$r render scenes/calibration_cube.toml -o "$o/cube-0.png" --width 320 --height 320 --samples 4 --set 'group.cube.velocity=[0, 0, 0]' $q
$r render scenes/calibration_cube.toml -o "$o/cube-0.5.png" --width 320 --height 320 --samples 4 --set 'group.cube.velocity=[0.5, 0, 0]' $q
$r render scenes/calibration_cube.toml -o "$o/cube-0.9.png" --width 320 --height 320 --samples 4 --set 'group.cube.velocity=[0.9, 0, 0]' $q
$r render scenes/calibration_cube.toml -o "$o/cube-0.99.png" --width 320 --height 320 --samples 4 --set 'group.cube.velocity=[0.99, 0, 0]' $q
$r render scenes/lattice.toml -o "$o/lattice-up-0.5.png" --width 320 --height 320 --samples 4 --set 'group.lattice.velocity=[-0.5, 0, 0]' --set 'camera.direction=[1, 0, 1]' $q
$r render scenes/lattice.toml -o "$o/lattice-upright-0.5.png" --width 320 --height 320 --samples 4 --set 'group.lattice.velocity=[-0.5, 0, 0]' --set 'camera.direction=[1, -1, 1]' $q
# Light as a camera records it: the same scene with neither effect, the Doppler shift alone, both.
$r render scenes/passing_spheres.toml -o "$o/spheres-rgb.png" --width 576 --height 192 --samples 4 --set render.doppler=false --set render.searchlight=false $q
$r render scenes/passing_spheres.toml -o "$o/spheres-doppler.png" --width 576 --height 192 --samples 4 --set render.searchlight=false $q
$r render scenes/passing_spheres.toml -o "$o/spheres-doppler-searchlight.png" --width 576 --height 192 --samples 4 $q
# The fast-moving planet: at rest, and at 0.9c as it approaches.
$r render scenes/planet.toml -o "$o/planet-0.png" --width 320 --height 320 --samples 4 --set 'group.planet.velocity=[0, 0, 0]' --set 'camera.direction=[0, 1, 0]' $q
$r render scenes/planet.toml -o "$o/planet-0.9.png" --width 320 --height 320 --samples 4 $q
# A flight through the star field at 0.99c, beside the same sky from a camera at rest.
$r render scenes/star_flight.toml -o "$o/stars-0.png" --width 384 --height 216 --set 'camera.velocity=[0, 0, 0]' $q
$r render scenes/star_flight.toml -o "$o/stars-0.99.png" --width 384 --height 216 $q
# A scene modelled and keyed in Blender, exported as glTF, passing at 0.9c.
$r render scenes/fleet.toml -o "$o/fleet-0.9.png" --width 480 --height 270 $q
# A textured OBJ model at rest and approaching at 0.9c, against the stars.
$r render scenes/rocket.toml -o "$o/rocket-0.png" --width 384 --height 216 --samples 4 --set 'group.rocket.velocity=[0, 0, 0]' --set 'camera.direction=[0, 1, 0]' $q
$r render scenes/rocket.toml -o "$o/rocket-0.9.png" --width 384 --height 216 --samples 4 $q
# Glowing spheres passing over a floor, lit by the path integrator: at rest, and at 0.7c.
$r render scenes/glowing_pass.toml -o "$o/glow-0.png" --width 384 --height 216 --samples 256 --set 'group.lamps.velocity=[0, 0, 0]' $q
$r render scenes/glowing_pass.toml -o "$o/glow-0.7.png" --width 384 --height 216 --samples 256 $q
# The radar world: the bar array lit by a flash riding with the camera, left on and pulsed.
$r render scenes/radar_bars.toml -o "$o/optical-bars.png" --width 320 --height 320 --samples 4 --set 'camera.flash.on=[[-100, 100]]' $q
$r render scenes/radar_bars.toml -o "$o/radar-bars.png" --width 320 --height 320 --samples 4 $q
# A planet spinning with its equator at 0.9c, beside it still.
$r render scenes/spinning_planet.toml -o "$o/spin-0.png" --width 384 --height 216 --samples 4 --set 'group.planet.object.planet.spin.omega=0' $q
$r render scenes/spinning_planet.toml -o "$o/spin-0.9.png" --width 384 --height 216 --samples 4 $q
# The spoked wheel, still and with its rim at 0.9c.
$r render scenes/spoked_wheel.toml -o "$o/wheel-0.png" --width 320 --height 240 --set 'group.wheel.object.wheel.spin.omega=0' $q
$r render scenes/spoked_wheel.toml -o "$o/wheel-0.9.png" --width 320 --height 240 $q
# The lattice at 0.9c with the shutter open for 0.12 of the camera's time.
$r render scenes/lattice.toml -o "$o/lattice-shutter-0.9.png" --width 320 --height 320 --samples 32 --set 'group.lattice.velocity=[-0.9, 0, 0]' --set camera.shutter=0.12 $q
# Films: six frames of each at 320x180, each to a plain name (--frames K), joined 3x2.
film=$(mktemp -d)
six() {
  local scene=$1 name=$2; shift 2
  local frames=()
  for k in "$@"; do
    $r render "scenes/$scene.toml" -o "$film/$name-$k.png" --width 320 --height 180 --frames "$k" $q
    frames+=("$film/$name-$k.png")
  done
  # (Without the command line in the metadata: it names a temporary folder, and the
  # pictures must come out the same bytes each time.)
  oiiotool --nosoftwareattrib "${frames[@]}" --mosaic 3x2 -o "$o/$name.png"
}
six planet_film planet-film 12 18 24 30 36 46
six twin_film twin-film 14 22 40 56 76 96
six accelerating_train accelerating-train 8 20 32 44 56 68
rm -rf "$film"
# The viewer's page in headless Chromium, after the browser test's slider move and click.
"$(dirname "$0")/browser-test.sh" "$r" "$o/viewer.png"
echo "wrote $(ls "$o" | wc -l) images to $o"
