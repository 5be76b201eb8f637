"""Run the README's first ```python block (the Python quick start) as a user would."""

import re
import sys
from pathlib import Path

text = Path(sys.argv[1]).read_text(encoding="utf-8")
block = re.search(r"```python\n(.*?)```", text, re.S)
if block is None:
    sys.exit("README has no ```python block")
exec(compile(block.group(1), "README.md (python block)", "exec"), {"__name__": "__main__"})
print("README snippet ok")
