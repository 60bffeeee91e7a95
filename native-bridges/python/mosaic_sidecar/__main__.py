"""`python -m mosaic_sidecar`: serve the framed protocol on stdin/stdout until EOF or shutdown."""

import sys

from .server import main

sys.exit(main())
