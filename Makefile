# The two set-up commands of the README: `make demo` and `make test`. Each installs what it
# needs first (scripts/setup.sh).

CARGO ?= cargo
OUT ?= out

.PHONY: setup demo test lint bench images docs film python

setup:
	@scripts/setup.sh

# Render the paper's lattice (Hsiung & Dunn 1989, Figure 16: beta = 0.9) to PNG and EXR, and
# white spheres passing at 0.5c as a camera records them (Doppler shift and searchlight).
demo: setup
	$(CARGO) build --release
	mkdir -p $(OUT)
	./target/release/rest-embree render scenes/lattice.toml -o $(OUT)/lattice-0.9.png --set 'group.lattice.velocity=[-0.9, 0, 0]'
	./target/release/rest-embree render scenes/lattice.toml -o $(OUT)/lattice-0.9.exr --set 'group.lattice.velocity=[-0.9, 0, 0]'
	./target/release/rest-embree render scenes/passing_spheres.toml -o $(OUT)/passing-spheres.png
	@echo "demo: wrote $(OUT)/lattice-0.9.png, $(OUT)/lattice-0.9.exr and $(OUT)/passing-spheres.png"

# The formatting and the lints alone, as `make test` runs them (in target/lint).
lint:
	@CARGO=$(CARGO) scripts/lint.sh

# Every test, optimised, once, in the build with Embree, and beside it the formatting and the
# lints (the library alone and the whole program: scripts/lint.sh); then a real one-node SLURM
# cluster runs a film and a tiled still through `rest-embree farm slurm` (scripts/slurm-test.sh;
# it needs root, and says so when skipped). The Python package's tests follow (pytest, and the
# example notebook; its virtual environment is filled in the background meanwhile).
# `--release` builds the tests in target/release beside `make demo`'s binary, on the same
# optimised dependencies: one optimised build of everything, not a second one in target/debug
# with full debug info. Blender 5 (bpy, from PyPI) downloads in the background meanwhile, for
# the last check: every documented pass as Blender's compositor takes it
# (scripts/blender-test.sh). Before it, headless Chromium drives the viewer's page: a slider
# moved, a frame awaited, a pixel clicked (scripts/browser-test.sh).
test: setup
	@mkdir -p target && (scripts/blender-test.sh --install >target/bpy-install.log 2>&1 &)
	@(scripts/python-test.sh --prepare >target/pyenv-install.log 2>&1 &)
	@# The code as the house keeps it: formatted, and no lint in the library alone (no Embree,
	@# no command line: what a program that links it builds), in the whole program or in the
	@# Python crate (scripts/lint.sh). They run beside the builds, in a target directory of
	@# their own at the lowest priority, on the cores the build leaves idle; their output and
	@# their verdict come at the end. The build without Embree is checked there, every target
	@# of it, and its tests are not run again: they are the same tests over the same code but
	@# for a few lines chosen by the feature (the backends' names and the error naming the
	@# feature, which the tests check in every build: src/tests/backend_names.rs). Running
	@# them cost a second optimised build of the library (docs/testing.md has the times).
	@CARGO=$(CARGO) scripts/lint.sh --start
	@# Every package's tests, and the one build of the library the steps below share: the ISA
	@# loop names the workspace too, and the Python package's build finds the library built
	@# with the same features (naming the root package alone, the Python crate's dependencies
	@# unify features otherwise, and one or the other rebuilt the library: 40-57 s).
	$(CARGO) test --release --workspace
	@# The backend's conformance suite (grazing packets against single rays, analytic hits)
	@# and the meshes' (held meshes are Embree triangle geometries) again under each of
	@# Embree's code paths this CPU has: their packet widths and slab tests differ
	@# (src/tests/every_isa.rs renders under each in-process). The CPU's best, which Embree
	@# runs when REST_EMBREE_ISA is unset, ran them above with the whole suite.
	@best=$$(./target/release/rest-embree backends | sed -n "s/.*instruction set \([^ ]*\) (the CPU's best.*/\1/p"); \
	for isa in sse2 sse4.2 avx avx2 avx512; do \
	  if [ "$$isa" = "$$best" ]; then \
	    echo "conformance under REST_EMBREE_ISA=$$isa: the CPU's best, run above"; \
	  elif REST_EMBREE_ISA=$$isa ./target/release/rest-embree backends >/dev/null 2>&1; then \
	    echo "conformance under REST_EMBREE_ISA=$$isa"; \
	    REST_EMBREE_ISA=$$isa $(CARGO) test --release --workspace --test suite -q -- backend_conformance:: meshes:: gltf::a_ radar:: worldline:: shutter:: spin:: acceleration:: wigner_rotation:: turning:: path::lanes::the_lanes_change_no_picture || exit 1; \
	  fi; \
	done
	@# The SLURM cluster's test waits on its scheduler most of its time: it runs beside the
	@# browser's, Python's and Blender's, its output shown when it ends.
	@echo "scripts/slurm-test.sh target/release/rest-embree (beside the next three; its output follows them)"
	@scripts/slurm-test.sh target/release/rest-embree >target/slurm-test.log 2>&1 & slurm=$$!; \
	  scripts/browser-test.sh target/release/rest-embree && \
	  scripts/python-test.sh target/release/rest-embree && \
	  scripts/blender-test.sh target/release/rest-embree; rest=$$?; \
	  wait $$slurm; cluster=$$?; cat target/slurm-test.log; \
	  [ $$cluster -eq 0 ] || echo "make test: FAILED: scripts/slurm-test.sh (above)" >&2; \
	  [ $$rest -eq 0 ] && [ $$cluster -eq 0 ]
	@scripts/lint.sh --wait

# The Python package (python/): `import rest_embree` in the virtual environment VENV (default
# .venv here); see docs/python.md.
python: setup
	@scripts/python-install.sh

# A film's frames as an MP4 (ffmpeg): make film FRAMES='film/frame-%04d.png' FPS=24 MP4=film.mp4
FRAMES ?= film/frame-%04d.png
FPS ?= 24
MP4 ?= film.mp4
film:
	@command -v ffmpeg >/dev/null 2>&1 || { echo "make film: ffmpeg is not installed; on Debian: sudo apt-get install ffmpeg" >&2; exit 1; }
	ffmpeg -y -framerate $(FPS) -i '$(FRAMES)' -pix_fmt yuv420p -vf 'pad=ceil(iw/2)*2:ceil(ih/2)*2' $(MP4)

bench: setup
	$(CARGO) build --release
	./target/release/rest-embree bench --threads 2

# Everything in docs/ that is generated: the bench's figures (docs/bench, docs/performance.md,
# with the path integrator beside Mitsuba 3 where it is installed),
# the accuracy table (docs/ACCURACY.md) and the README's pictures (docs/img).
docs: setup
	$(CARGO) build --release
	./target/release/rest-embree bench --threads 2 --out docs/bench
	@# The path integrator beside Mitsuba 3, where it is installed (a bench, not a test).
	@if python3 -c 'import mitsuba, OpenEXR, numpy' 2>/dev/null; then \
	  python3 scripts/mitsuba-compare.py --out docs/bench/mitsuba.md; \
	  python3 scripts/mitsuba-terrain.py --out docs/bench/terrain.md; \
	else \
	  echo "docs: Mitsuba 3 not installed (pip install mitsuba==3.9.1 OpenEXR numpy; apt-get install libllvm19): docs/bench/mitsuba.md and terrain.md kept as they are"; \
	fi
	scripts/performance-doc.sh
	scripts/accuracy-table.sh
	scripts/readme-images.sh

# The pictures in the README (docs/img).
images: setup
	$(CARGO) build --release
	scripts/readme-images.sh
