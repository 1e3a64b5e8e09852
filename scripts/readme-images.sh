#!/usr/bin/env bash
# Render the README's pictures (docs/img) from the scenes. Needs a release build.
set -euo pipefail
cd "$(dirname "$0")/.."
r=./target/release/rest-embree
o=docs/img
mkdir -p "$o"
size=(--width 320 --height 320 --samples 4 --quiet)
for b in 0 0.5 0.9 0.99; do
  $r render scenes/calibration_cube.toml -o "$o/cube-$b.png" "${size[@]}" --set "group.cube.velocity=[$b, 0, 0]"
  $r render scenes/bar_array.toml -o "$o/bars-$b.png" "${size[@]}" --set "group.bars.velocity=[$b, 0, 0]"
  $r render scenes/lattice.toml -o "$o/lattice-$b.png" "${size[@]}" --set "group.lattice.velocity=[-$b, 0, 0]"
done
$r render scenes/lattice.toml -o "$o/lattice-up-0.5.png" "${size[@]}" --set 'group.lattice.velocity=[-0.5, 0, 0]' --set 'camera.direction=[1, 0, 1]'
$r render scenes/lattice.toml -o "$o/lattice-upright-0.5.png" "${size[@]}" --set 'group.lattice.velocity=[-0.5, 0, 0]' --set 'camera.direction=[1, -1, 1]'
# Light as a camera records it: the same scene with neither effect, the Doppler shift alone, both.
wide=(--width 576 --height 192 --samples 4 --quiet)
$r render scenes/passing_spheres.toml -o "$o/spheres-rgb.png" "${wide[@]}" --set render.doppler=false --set render.searchlight=false
$r render scenes/passing_spheres.toml -o "$o/spheres-doppler.png" "${wide[@]}" --set render.searchlight=false
$r render scenes/passing_spheres.toml -o "$o/spheres-doppler-searchlight.png" "${wide[@]}"
# The fast-moving planet: at rest, and at 0.9c as it approaches (scenes/planet.toml).
$r render scenes/planet.toml -o "$o/planet-0.png" "${size[@]}" --set 'group.planet.velocity=[0, 0, 0]' --set 'camera.direction=[0, 1, 0]'
$r render scenes/planet.toml -o "$o/planet-0.9.png" "${size[@]}"
# A flight through the star field at 0.99c, beside the same sky from a camera at rest.
sky=(--width 384 --height 216 --quiet)
$r render scenes/star_flight.toml -o "$o/stars-0.png" "${sky[@]}" --set 'camera.velocity=[0, 0, 0]'
$r render scenes/star_flight.toml -o "$o/stars-0.99.png" "${sky[@]}"
# A textured OBJ model at rest and approaching at 0.9c, against the stars.
$r render scenes/rocket.toml -o "$o/rocket-0.png" "${sky[@]}" --samples 4 --set 'group.rocket.velocity=[0, 0, 0]' --set 'camera.direction=[0, 1, 0]'
$r render scenes/rocket.toml -o "$o/rocket-0.9.png" "${sky[@]}" --samples 4
# Glowing spheres passing over a floor, lit by the path integrator: at rest, and at 0.7c.
glow=(--width 384 --height 216 --samples 256 --quiet)
$r render scenes/glowing_pass.toml -o "$o/glow-0.png" "${glow[@]}" --set 'group.lamps.velocity=[0, 0, 0]'
$r render scenes/glowing_pass.toml -o "$o/glow-0.7.png" "${glow[@]}"
# The radar world: the bar array lit by a flash riding with the camera, left on and pulsed.
$r render scenes/radar_bars.toml -o "$o/optical-bars.png" "${size[@]}" --set 'camera.flash.on=[[-100, 100]]'
$r render scenes/radar_bars.toml -o "$o/radar-bars.png" "${size[@]}"
# Six frames of the planet film, as one picture.
film=$(mktemp -d)
$r render scenes/planet_film.toml -o "$film/planet-####.png" --width 320 --height 180 --quiet --frames 12..46
frames=()
for k in 12 18 24 30 36 46; do frames+=("$film/planet-$(printf %04d $k).png"); done
oiiotool "${frames[@]}" --mosaic 3x2 -o "$o/planet-film.png"
rm -rf "$film"
# A planet spinning with its equator at 0.9c, beside it still.
$r render scenes/spinning_planet.toml -o "$o/spin-0.png" "${sky[@]}" --samples 4 --set 'group.planet.object.planet.spin.omega=0'
$r render scenes/spinning_planet.toml -o "$o/spin-0.9.png" "${sky[@]}" --samples 4
# Six frames of the travelling twin's film, on its own clock (scenes/twin_film.toml).
film=$(mktemp -d)
frames=()
for k in 14 22 40 56 76 96; do
  $r render scenes/twin_film.toml -o "$film/twin-####.png" --width 320 --height 180 --quiet --frames "$k"
  frames+=("$film/twin-$(printf %04d $k).png")
done
oiiotool "${frames[@]}" --mosaic 3x2 -o "$o/twin-film.png"
rm -rf "$film"
# The lattice at 0.9c with the shutter open for 0.12 of the camera's time.
$r render scenes/lattice.toml -o "$o/lattice-shutter-0.9.png" --width 320 --height 320 --samples 32 --quiet --set 'group.lattice.velocity=[-0.9, 0, 0]' --set camera.shutter=0.12
# Six frames of the train accelerating Born-rigidly past a camera at rest.
film=$(mktemp -d)
frames=()
for k in 8 20 32 44 56 68; do
  $r render scenes/accelerating_train.toml -o "$film/train-####.png" --width 320 --height 180 --quiet --frames "$k"
  frames+=("$film/train-$(printf %04d $k).png")
done
oiiotool "${frames[@]}" --mosaic 3x2 -o "$o/accelerating-train.png"
rm -r "$film"
# The spoked wheel, still and with its rim at 0.9c.
$r render scenes/spoked_wheel.toml -o "$o/wheel-0.png" --width 320 --height 240 --quiet --set 'group.wheel.object.wheel.spin.omega=0'
$r render scenes/spoked_wheel.toml -o "$o/wheel-0.9.png" --width 320 --height 240 --quiet
# The viewer's page in headless Chromium, after the browser test's slider move and click.
"$(dirname "$0")/browser-test.sh" "$r" "$o/viewer.png"
echo "wrote $(ls "$o" | wc -l) images to $o"
