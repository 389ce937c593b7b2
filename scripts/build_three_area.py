"""Write engines/three/src/generated/rt_lit_area.js, the three.js patch's GLSL ES 3.00 emitted from the IR.

RT Lit's area-light lobes for engines/three's patchAreaLights (core/export/three_area.py).

    python scripts/build_three_area.py [--check]

``--check`` writes nothing and exits 1 when the committed file differs from what the IR gives."""
import argparse
import sys
from pathlib import Path

from rt_lookdev.core.export import three_area

REPO = Path(__file__).resolve().parents[1]


def main(argv):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--check", action="store_true", help="compare with the committed file; write nothing")
    args = parser.parse_args(argv)
    path = REPO / three_area.MODULE_PATH
    text = three_area.module_text()
    if args.check:
        same = path.is_file() and path.read_text() == text
        print(f"{path}: {'up to date' if same else 'differs from the IR: run python scripts/build_three_area.py'}")
        return 0 if same else 1
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(text)
    print(f"wrote {path} ({len(text)} characters)")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
