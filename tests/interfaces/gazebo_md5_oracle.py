"""Run by Debian's /usr/bin/python3: genmsg (what genpy builds on) computes the md5sums of the
gazebo_msgs definitions we ship, from our .msg/.srv files. Debian packages no gazebo_msgs, and no
.msg files of geometry_msgs either: the types ours refer to (Pose, Twist, Wrench, Header,
ColorRGBA, JointTrajectory, ...) are registered from Debian's own generated classes' full texts.
Prints {type: md5} as JSON. Argument: our interfaces directory."""

import importlib
import json
import os
import sys

import genmsg
import genmsg.msg_loader as loader

ROOTS = (
    "geometry_msgs/Pose",
    "geometry_msgs/Twist",
    "geometry_msgs/Wrench",
    "geometry_msgs/Point",
    "geometry_msgs/Vector3",
    "std_msgs/Header",
    "std_msgs/ColorRGBA",
    "trajectory_msgs/JointTrajectory",
)
SEPARATOR = "=" * 80 + "\n"


def register_debian(ctx, type_name):
    pkg, name = type_name.split("/")
    cls = getattr(importlib.import_module(pkg + ".msg"), name)
    blocks = cls._full_text.split(SEPARATOR)
    texts = {type_name: blocks[0]}
    for block in blocks[1:]:
        head, _, body = block.partition("\n")
        texts[head[len("MSG: ") :].strip()] = body
    for full, text in texts.items():
        if not ctx.is_registered(full):
            ctx.register(full, loader.load_msg_from_string(ctx, text, full))


def main():
    ours = sys.argv[1]
    ctx = genmsg.MsgContext.create_default()
    for root in ROOTS:
        register_debian(ctx, root)
    search = {"gazebo_msgs": [os.path.join(ours, "gazebo_msgs", "msg")]}
    out = {}
    for kind in ("msg", "srv"):
        folder = os.path.join(ours, "gazebo_msgs", kind)
        for name in sorted(os.listdir(folder)):
            stem, ext = os.path.splitext(name)
            full = "gazebo_msgs/" + stem
            path = os.path.join(folder, name)
            if ext == ".msg":
                spec = loader.load_msg_from_file(ctx, path, full)
                ctx.register(full, spec)
            else:
                spec = loader.load_srv_from_file(ctx, path, full)
            loader.load_depends(ctx, spec, search)
            out[full] = genmsg.compute_md5(ctx, spec)
    print(json.dumps(out))


if __name__ == "__main__":
    main()
