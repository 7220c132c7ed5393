"""The ``blendsynth`` command installed with the wheel: runs the Rust CLI binary bundled
in the package (``blendsynth/bin/blendsynth``), replacing this process."""

from __future__ import annotations

import os
import sys
from pathlib import Path


def binary() -> Path:
    """The bundled CLI binary."""
    name = "blendsynth.exe" if os.name == "nt" else "blendsynth"
    return Path(__file__).resolve().parent / "bin" / name


def main() -> None:
    exe = binary()
    if not exe.is_file():
        sys.stderr.write(
            f"error: this blendsynth package has no bundled command ({exe} is missing): "
            "build the wheel with .ci/python.sh, or install the CLI with `cargo install --path .`\n"
        )
        raise SystemExit(1)
    args = [os.fspath(exe), *sys.argv[1:]]
    if os.name == "nt":  # pragma: no cover - no exec on Windows
        import subprocess

        raise SystemExit(subprocess.call(args))
    os.execv(args[0], args)


if __name__ == "__main__":
    main()
