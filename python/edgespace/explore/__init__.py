"""python/edgespace/explore — explore a study by hand: `edgespace explore
STORE` (a local web page, server.py) and edgespace.widgets.explore (Jupyter)
share the Explorer of core.py: sliders over the PCA's components, stored
differences and model coefficients, each position embedded at once near its
prior (warm), a row's own mesh on a click, heat maps, and saving a shape.

    python3 -m edgespace.explore STORE [--port N] [--pca NAME]   # what the command runs
"""
from .core import HEAT_MAPS, Direction, Explorer, RequestError, Shape

__all__ = ["Explorer", "Direction", "Shape", "RequestError", "HEAT_MAPS", "serve"]


def serve(store, pca=None, host="127.0.0.1", port=0, warm=True, fast=True, cache=True, pcs=20,
          ready=None, log=None):
    """Run the explorer's web server on `store` until interrupted (Ctrl-C,
    SIGTERM); ready(url) is called once it listens. What `edgespace explore`
    runs; __main__.py parses its options."""
    from .__main__ import run
    return run(store, pca=pca, host=host, port=port, warm=warm, fast=fast, cache=cache, pcs=pcs,
               ready=ready, log=log)
