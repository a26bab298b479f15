#!/usr/bin/env python3
"""Forward-kinematics reference data from Pinocchio, the oracle for vworks-model.

For each built-in model (crates/model/models/*.urdf) and three third-party URDFs shipped
in the pybullet wheel (pybullet_data: kuka_iiwa, franka_panda, xarm6), this loads the
URDF with Pinocchio, draws 100 joint vectors uniformly within the joint limits (a fixed
seed), and records the pose of every link. The Rust test
crates/model/tests/oracle.rs loads the same URDFs with vworks and compares every link
frame to 1e-9 m.

    scripts/pin_reference.py           # (re)write crates/model/test_data/reference/*.json
    scripts/pin_reference.py --check   # fail unless the committed files match Pinocchio

Needs: pip install pin pybullet numpy.
"""

import json
import math
import os
import sys

import numpy as np
import pinocchio as pin
import pybullet_data

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
OUT = os.path.join(ROOT, "crates", "model", "test_data", "reference")
SAMPLES = 100

# (name, where the URDF is, URDF path, tool link or None for the chain's end)
MODELS = [(n, "builtin", f"crates/model/models/{n}.urdf", None) for n in
          ["irb120", "kr6r900", "lrmate200id", "ur5", "turntable", "track"]] + [
    ("kuka_iiwa", "pybullet_data", "kuka_iiwa/model.urdf", None),
    ("franka_panda", "pybullet_data", "franka_panda/panda.urdf", "panda_hand"),
    ("xarm6", "pybullet_data", "xarm/xarm6_robot.urdf", None),
]


def urdf_file(where, rel):
    base = ROOT if where == "builtin" else pybullet_data.getDataPath()
    return os.path.join(base, rel)


def chain_end(model):
    """The tool link when none is named: follow the only child until a leaf."""
    children = {}
    for f in model.frames:
        if f.type == pin.FrameType.BODY:
            children.setdefault(f.parentFrame, []).append(f)
    frame = next(f for f in model.frames if f.type == pin.FrameType.BODY)
    while True:
        idx = model.getFrameId(frame.name)
        # Children of a body: frames whose parent frame is a joint/fixed frame whose
        # parent is this body.
        kids = [f for f in model.frames if f.type == pin.FrameType.BODY and
                f.name != frame.name and
                model.frames[f.parentFrame].parentFrame == idx]
        if not kids:
            return frame.name
        if len(kids) > 1:
            raise SystemExit(f"{model.name}: the tree branches at {frame.name}; name the tool link")
        frame = kids[0]


def quiet_build(path):
    """buildModelFromUrdf, without urdfdom's complaints about <capsule> collision elements
    (the kinematic model does not need collision geometry)."""
    sys.stderr.flush()
    saved = os.dup(2)
    devnull = os.open(os.devnull, os.O_WRONLY)
    os.dup2(devnull, 2)
    try:
        return pin.buildModelFromUrdf(path)
    finally:
        os.dup2(saved, 2)
        os.close(devnull)
        os.close(saved)


def reference(name, where, rel, tool):
    model = quiet_build(urdf_file(where, rel))
    data = model.createData()
    tool = tool or chain_end(model)
    tool_joint = model.frames[model.getFrameId(tool)].parentJoint
    # The axes: the joints supporting the tool, root first.
    axes = [model.names[j] for j in model.supports[tool_joint] if j != 0]
    rng = np.random.default_rng(20261121)
    samples = []
    for _ in range(SAMPLES):
        q = pin.neutral(model)
        qa = []
        for jname in axes:
            j = model.getJointId(jname)
            jm = model.joints[j]
            lo = model.lowerPositionLimit[jm.idx_q]
            hi = model.upperPositionLimit[jm.idx_q]
            if jm.nq == 2:  # continuous: cos/sin
                v = rng.uniform(-math.pi, math.pi)
                q[jm.idx_q], q[jm.idx_q + 1] = math.cos(v), math.sin(v)
            else:
                lo, hi = max(lo, -2 * math.pi), min(hi, 2 * math.pi)
                v = rng.uniform(lo, hi)
                q[jm.idx_q] = v
            qa.append(float(v))
        pin.framesForwardKinematics(model, data, q)
        links = {}
        for fid, f in enumerate(model.frames):
            if f.type == pin.FrameType.BODY:
                m = data.oMf[fid]
                links[f.name] = [float(x) for x in m.translation] + [float(x) for x in m.rotation.flatten()]
        samples.append({"q": qa, "links": links})
    return {"model": name, "where": where, "urdf": rel, "tool": tool, "axes": axes,
            "pinocchio": pin.__version__, "samples": samples}


def main():
    check = "--check" in sys.argv
    os.makedirs(OUT, exist_ok=True)
    bad = []
    for name, where, rel, tool in MODELS:
        ref = reference(name, where, rel, tool)
        path = os.path.join(OUT, f"{name}.json")
        if check:
            with open(path) as f:
                old = json.load(f)
            same = old["axes"] == ref["axes"] and len(old["samples"]) == len(ref["samples"]) and all(
                np.allclose(a["q"], b["q"], atol=1e-12) and a["links"].keys() == b["links"].keys() and
                all(np.allclose(a["links"][k], b["links"][k], atol=1e-12) for k in a["links"])
                for a, b in zip(old["samples"], ref["samples"]))
            print(f"{name}: {'matches' if same else 'DIFFERS from'} Pinocchio {pin.__version__}")
            if not same:
                bad.append(name)
        else:
            with open(path, "w") as f:
                json.dump(ref, f, separators=(",", ":"))
                f.write("\n")
            print(f"wrote {path}: {len(ref['samples'])} samples, {len(ref['samples'][0]['links'])} links")
    if bad:
        raise SystemExit(f"reference data out of date for {bad}: run scripts/pin_reference.py")


if __name__ == "__main__":
    main()
