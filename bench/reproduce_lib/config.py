"""bench/reproduce_lib/config.py — what bench/reproduce renders: the paper's
scenes (profile rows and crops), the methods and their labels, the budgets of
the quick and full profiles, the seeds of test images and references."""
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
TDPM = os.path.join(ROOT, "build", "tdpm")

# ---------------------------------------------------------------------------
# Scenes. Profile rows and crops are fractions of the image height/width, so
# they hold at any resolution. They were found by scanning rows of `time`
# against `standard` (cube) or against the path tracer (the others, whose
# caustics the path tracer lacks) at 320x240 for the row with the most
# added light, and by looking at the images.
# ---------------------------------------------------------------------------
SCENES = {
    "cube": {
        "file": "scenes/cube-caustic.json",
        "paper": "moving cube lit through a glass sphere",
        "photons": 900000, "frames": 20, "k": 200, "fraction": 0.5,  # the paper's settings
        "reference": "pathtrace",
        # the caustic on the top face (rows 225-300 of 480 over the shutter)
        "profiles": [("caustic", 130 / 240)],
        "crop": (0.40, 0.44, 0.20, 0.21),
    },
    "truck": {
        "file": "scenes/truck-laser.json",
        "paper": "truck, laser reflected off its back",
        "photons": 40000, "frames": 9,  # the paper's; k and fraction from the scene (100, 0.5)
        "reference": "accumulation",
        # the laser spot seen in the mirror (pixel ~ (364, 244) of 640x480) and the streak on the road
        "profiles": [("mirror-spot", 244 / 480), ("streak", 165 / 240)],
        "crop": (0.22, 0.46, 0.40, 0.30),
    },
    # Not a scene file: truck-laser.json with the sun removed, written to
    # results/scenes/ at run time. In the full scene the 1,500 W area sun takes
    # nearly all of the 40,000 caustic photons (projection-map emission shares
    # them by power), so the 14 W laser's streak is spread by k-NN into a
    # glow of the maximum search radius; with the laser alone the streak and the
    # spot in the mirror are resolved, as in the paper.
    "truck-laser-only": {
        "file": "scenes/truck-laser.json", "derive_lights": ["laser"],
        "paper": "truck, laser only (derived: the sun removed)",
        "photons": 40000, "frames": 9,
        "reference": "accumulation",
        "profiles": [("mirror-spot", 244 / 480), ("streak", 165 / 240)],
        "crop": (0.0, 0.40, 0.70, 0.42),
    },
    "car": {
        "file": "scenes/car-following.json",
        "paper": "car following a truck, camera moving with it",
        "photons": None, "frames": None,  # the scene's render block (100,000 photons, 8 frames)
        "reference": "accumulation",
        # the ball's caustic in its shadow on the road
        "profiles": [("ball-caustic", 188 / 240)],
        "crop": (0.40, 0.68, 0.30, 0.24),
    },
    "room": {
        "file": "scenes/static-room.json",
        "paper": "(none: the no-motion case)",
        "photons": None, "frames": None,  # the scene's render block (200,000 photons, k 100)
        "reference": "pathtrace",
        # the lamp's caustic through the glass ball on the table top
        "profiles": [("table-caustic", 142 / 240)],
        "crop": (0.28, 0.52, 0.20, 0.14),
    },
}

# method name -> (tdpm arguments, consistent?, label)
METHODS = {
    "static": (["-m", "static"], "no", "static"),
    "accumulation": (["-m", "accumulation"], "as frames → ∞", "accumulation"),
    "standard": (["-m", "standard"], "no", "standard"),
    "time": (["-m", "time", "--search", "twopass"], "yes", "time (two-pass)"),
    "time-4d": (["-m", "time", "--search", "4d"], "yes", "time (4d)"),
}
# --progressive (issue 10): the pass loops, swept by pass count (each pass: 1/8 of
# the scene's photon budget and 1 spp), beside the fixed-budget methods.
PROGRESSIVE = {
    "p-time": (["-m", "time", "--progressive"], "yes", "time --progressive"),
    "p-accumulation": (["-m", "accumulation", "--progressive"], "yes", "accumulation --progressive"),
    "p-standard": (["-m", "standard", "--progressive"], "no", "standard --progressive"),
}
PROGRESSIVE_PASSES = [2, 8, 32, 128]
PROGRESSIVE_PHOTON_FRACTION = 8
CONSISTENT = ["accumulation", "time", "time-4d", "pathtrace", "p-time", "p-accumulation"]
COLORS = {"static": "#888888", "accumulation": "#1f77b4", "standard": "#ff7f0e",
          "time": "#d62728", "time-4d": "#9467bd", "pathtrace": "#2ca02c",
          "p-time": "#8c564b", "p-accumulation": "#17becf", "p-standard": "#bcbd22"}

# Budgets. "spp" None: the scene's own.
PROFILES = {
    "quick": {
        "resolution": "160x120", "spp": 4,
        # references: two independent halves (seeds 1 and 3), each with these budgets
        "ref_pt_spp": {"cube": 4096, "room": 1024},
        # accumulation reference: frames, photons multiplier (of the scene's budget), spp
        "ref_acc": {"frames": 64, "photon_mult": 16, "spp": 128},
        "sweep_scales": [0.25, 0.5, 1, 2],
        "sweep_pt_spp": [16, 64, 256],
        "sweep_scenes": ["cube", "truck", "truck-laser-only"],
        "sweep_methods": list(METHODS),
    },
    "full": {
        "resolution": None, "spp": None,
        "ref_pt_spp": {"cube": 4096, "room": 2048},
        "ref_acc": {"frames": 128, "photon_mult": 32, "spp": 256},
        "sweep_scales": [0.25, 0.5, 1, 2],
        "sweep_pt_spp": [64, 256, 1024],
        "sweep_scenes": ["cube", "truck", "truck-laser-only"],
        # static is left out: it converges to the wrong image, and at full
        # size its k-NN is the slowest (300 s on the cube; queries off the
        # plane of its one-time caustic prune badly), 14 of the sweep's minutes.
        "sweep_methods": ["accumulation", "standard", "time", "time-4d"],
    },
}

TEST_SEED = 2  # references use seeds 1 and 3 (its two halves): never the test images' samples
REF_SEEDS = (1, 3)
# A reference is converged enough for a measure when its own error is at
# most this fraction of the smallest error plotted with that measure.
REF_MAX_FRACTION = 0.1


BLOCK = 8  # block size for the block-averaged error


def method_label(name):
    """The label of a fixed-budget or progressive method (else the name itself)."""
    return METHODS[name][2] if name in METHODS else PROGRESSIVE[name][2] if name in PROGRESSIVE else name
