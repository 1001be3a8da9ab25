"""Where a waiting submission stands in the grading queue.

Workers claim the oldest queued submission first (by ``created_at``, then ``id``:
:meth:`.storage.Repository.claim`), so a queued submission's position is one more than
the number of queued ones ahead of it in that order: 1 is the next to be graded.
"""

from __future__ import annotations

import sqlalchemy as sa

from .storage import QUEUED, T


def position(repo, row: dict) -> int | None:
    """The queue position of ``row`` (1: graded next), or None when it is not queued."""
    if row.get("status") != QUEUED:
        return None
    ahead = sa.or_(
        T.c.created_at < row["created_at"],
        sa.and_(T.c.created_at == row["created_at"], T.c.id < row["id"]),
    )
    with repo.engine.connect() as conn:
        count = conn.execute(sa.select(sa.func.count()).select_from(T).where(T.c.status == QUEUED, ahead)).scalar()
    return int(count) + 1


def with_position(repo, row: dict, view: dict) -> dict:
    """``view`` (a submission as the API shows it) with ``position`` added while it is queued."""
    where = position(repo, row)
    if where is not None:
        view["position"] = where
    return view
