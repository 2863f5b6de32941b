"""Files the Python side writes: each writer its own temporary next to the target (docs/commands.md: outputs are
written to a temporary and renamed into place), so two writers of one target, in one process or two, never share
one."""
import os
import tempfile
from pathlib import Path


def unique_temporary(target: Path) -> Path:
    """A new empty file `.<name>.tmp-<pid>-<random>` in the target's folder, with the permissions a new file gets
    (umask), to be written and then renamed onto `target` (os.replace). Raises OSError as creating a file does."""
    fd, name = tempfile.mkstemp(prefix=f".{target.name}.tmp-{os.getpid()}-", dir=target.parent)
    os.close(fd)
    mask = os.umask(0o022)
    os.umask(mask)
    os.chmod(name, 0o666 & ~mask)
    return Path(name)
