"""Campbell benchmark as a study: runs `cvtfem bench campbell` cases and keeps the log.

    OPENBLAS_NUM_THREADS=1 .venv/bin/python studies/rotor/bench_campbell.py   # -> out/studies/rotor/bench.txt
"""
from pathlib import Path

from cvtfem.analysis.bench_campbell import run

OUT = Path("out/studies/rotor")


def main() -> None:
    OUT.mkdir(parents=True, exist_ok=True)
    lines: list[str] = []

    def log(text: str) -> None:
        print(text)
        lines.append(text)

    run(repeat=5, large=True, log=log)
    (OUT / "bench.txt").write_text("\n".join(lines) + "\n")
    print(f"wrote {OUT / 'bench.txt'}")


if __name__ == "__main__":
    main()
