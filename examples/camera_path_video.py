#!/usr/bin/env python3
"""A camera path to an MP4: bakes the Cornell box, writes a camera path file (the keyframe format
of `plenoptic render --path`) that walks into the box and looks around, renders its frames from
the light field and encodes them with ffmpeg (as `plenoptic render --path walk.json -o walk.mp4`
would). Without ffmpeg the frames are written as PNG files instead.

    python3 examples/camera_path_video.py [--seconds 4] [--fps 30] [--width 320] [--height 240]
                                          [--preset default] [--out out/examples]

Writes OUT/walk.json and OUT/walk.mp4 (or OUT/walk/0000.png, ...).
"""
import argparse
import json
import os
import shutil
import time

import plenoptic


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--seconds", type=float, default=4.0, help="length of the walk")
    parser.add_argument("--fps", type=float, default=30.0, help="frames per second")
    parser.add_argument("--width", type=int, default=320, help="frame width in pixels (even, for H.264)")
    parser.add_argument("--height", type=int, default=240, help="frame height in pixels (even, for H.264)")
    parser.add_argument("--preset", default="default", help="bake preset: draft, default, high")
    parser.add_argument("--threads", type=int, default=0, help="worker threads (0 = all)")
    parser.add_argument("--out", default=os.path.join("out", "examples"), help="output directory")
    args = parser.parse_args()
    os.makedirs(args.out, exist_ok=True)

    scene = plenoptic.load_scene("cornell")
    lf = plenoptic.bake(scene, preset=args.preset, threads=args.threads)
    print(lf)

    # The box is 556 mm wide, open towards -z; the camera starts outside, walks in, turns to
    # the tall block on the left and back to the short one on the right (times in seconds,
    # positions in the scene's millimetres; poses between keyframes are interpolated).
    t = args.seconds
    path = {"fps": args.fps, "keyframes": [
        {"time": 0.0, "eye": [278, 273, -800], "target": [278, 273, 0], "fov": 40},
        {"time": 0.4 * t, "eye": [278, 250, -250], "target": [278, 220, 300], "fov": 50},
        {"time": 0.7 * t, "eye": [300, 240, -150], "target": [160, 200, 380], "fov": 50},
        {"time": t, "eye": [260, 240, -150], "target": [400, 100, 200], "fov": 50}]}
    path_file = os.path.join(args.out, "walk.json")
    with open(path_file, "w") as f:
        json.dump(path, f, indent=1)

    start = time.perf_counter()
    frames = lf.render_path(path_file, width=args.width, height=args.height, threads=args.threads)
    seconds = time.perf_counter() - start
    print(f"{len(frames)} frames of {args.width}x{args.height} in {seconds:.2f} s "
          f"({1e3 * seconds / len(frames):.1f} ms per frame)")

    if shutil.which("ffmpeg"):
        video = os.path.join(args.out, "walk.mp4")
        plenoptic.write_video(video, frames, fps=args.fps)
        print(f"wrote {video}")
    else:
        folder = os.path.join(args.out, "walk")
        os.makedirs(folder, exist_ok=True)
        for k, frame in enumerate(frames):
            plenoptic.write_image(os.path.join(folder, f"{k:04d}.png"), frame)
        print(f"ffmpeg is not installed: wrote {len(frames)} PNG frames to {folder}/")


if __name__ == "__main__":
    main()
