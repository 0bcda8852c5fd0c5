import sys
from pathlib import Path

# Only the test helpers come from here; ballbal itself must be the installed wheel.
sys.path.insert(0, str(Path(__file__).parent))
