"""Build the demo lookdev scene and save it (``rt_lookdev.addon.demo_scene``).

    python scripts/build_demo_scene.py [--out out/demo/lookdev_demo.blend] [--lut-dir DIR]
                                       [--hdri forest|none] [--world-strength 0.5]
    blender --background --python scripts/build_demo_scene.py -- [same options]

``--help`` lists the options."""
import sys

from rt_lookdev.addon import demo_scene


def main(argv):
    if "--" in argv:                      # blender --background --python x.py -- args
        argv = argv[argv.index("--") + 1:]
    demo_scene.run(demo_scene.parse_args(argv))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
