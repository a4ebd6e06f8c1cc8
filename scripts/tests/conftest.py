"""What every test file shares: the harness package (scripts/dyadfmu) and the generator
package (modelDescription/dyadgen) importable, this checkout's ahead of any installed copy."""

import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2]

for _path in (ROOT / "modelDescription", ROOT / "scripts"):
    if str(_path) not in sys.path:
        sys.path.insert(0, str(_path))
