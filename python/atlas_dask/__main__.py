"""python3 -m atlas_dask GRAPH --tiles NX,NY --scheduler ADDRESS|local (see __init__.py)."""
import sys

from atlas_dask import main

# Spawned LocalCluster workers import this module again as __mp_main__: no driver there.
if __name__ == "__main__":
    sys.exit(main())
