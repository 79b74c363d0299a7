"""python3 -m atlas_dask GRAPH --tiles NX,NY --scheduler ADDRESS|local (see __init__.py)."""
import sys

from . import main

sys.exit(main())
