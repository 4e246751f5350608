"""``python -m navbook``: the book's command line (:mod:`navbook.cli`), with navlib's one-thread defaults."""

import os
import sys

from navlib import ONE_THREAD

for _name, _value in ONE_THREAD.items():
    os.environ.setdefault(_name, _value)

from navbook.cli import main  # noqa: E402  (after the thread defaults: numpy must not load first)

if __name__ == "__main__":
    sys.exit(main())
