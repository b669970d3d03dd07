"""The `btc` command `pip install` puts on the PATH: btc's command line,
run in this process by the package's native module."""

import sys

from ._btc import _main


def main() -> None:
    sys.exit(_main(sys.argv))


if __name__ == "__main__":
    main()
