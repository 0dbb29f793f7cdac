"""The notebook examples/notebooks/fricsim.ipynb runs from top to bottom
in a fresh kernel (nbclient), so that it never goes stale: every cell
executes without error and the cells that show results show them."""

from pathlib import Path

import nbformat
from nbclient import NotebookClient

ROOT = Path(__file__).resolve().parent.parent
NOTEBOOK = ROOT / "examples" / "notebooks" / "fricsim.ipynb"


def test_the_notebook_executes():
    notebook = nbformat.read(NOTEBOOK, as_version=4)
    # a kernel of the Python that runs the tests (the venv's)
    NotebookClient(
        notebook, timeout=600, kernel_name="python3", resources={"metadata": {"path": str(NOTEBOOK.parent)}}
    ).execute()
    code = [c for c in notebook.cells if c.cell_type == "code"]
    assert all(c.execution_count for c in code)
    outputs = [o for c in code for o in c.outputs]
    assert not [o for o in outputs if o.output_type == "error"]
    text = "".join(o.get("text", "") for o in outputs)
    assert "peak friction force" in text
    assert "direction_dependent" in text
    images = [o for o in outputs if "image/png" in o.get("data", {})]
    assert len(images) >= 2  # the run's plot and the diagnosis's fit
