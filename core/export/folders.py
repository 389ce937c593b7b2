"""Write a folder all at once: ``with replacing_folder(target) as tmp:`` fills a temporary sibling of
``target`` and, when the block ends without an error, puts it in ``target``'s place (an earlier folder
there is moved aside first, then deleted).  On an error or an interruption the temporary folder is
removed and ``target`` is as it was: nothing partial is ever visible under its name."""
from __future__ import annotations

import contextlib
import shutil
import tempfile
from pathlib import Path


@contextlib.contextmanager
def replacing_folder(target, error=OSError):
    """Yield a temporary folder beside ``target``; replace ``target`` with it when the block succeeds.
    ``error``: the exception class raised (with the reason) when the parent folder cannot be written."""
    target = Path(target)
    try:
        target.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{target.name}.partial-", dir=target.parent))
    except OSError as exc:
        raise error(f"cannot write into {target.parent}: {exc}") from None
    try:
        yield tmp
        if target.exists():
            old = Path(tempfile.mkdtemp(prefix=f".{target.name}.old-", dir=target.parent))
            old.rmdir()
            target.rename(old)
            tmp.rename(target)
            shutil.rmtree(old, ignore_errors=True)
        else:
            tmp.rename(target)
    except BaseException:
        shutil.rmtree(tmp, ignore_errors=True)
        raise
