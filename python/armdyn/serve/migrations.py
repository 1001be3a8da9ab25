"""The database schema, versioned: each migration is a function of an Alembic
:class:`~alembic.operations.Operations` object, applied in order at start-up.

Alembic's operations (not its script directory or ``env.py``) do the DDL, so the same
migration runs on SQLite (batch mode for ALTER) and PostgreSQL. The version applied
lives in the one-row table ``armdyn_schema``; :func:`upgrade` applies the missing
migrations inside one transaction, so a failed upgrade leaves the old schema intact.

To change the schema: append a function to :data:`MIGRATIONS` (never edit an old
one) and mirror the change in :mod:`.storage`'s table definitions.
"""

from __future__ import annotations

import sqlalchemy as sa
from alembic.operations import Operations
from alembic.runtime.migration import MigrationContext


def _v1_submissions(op: Operations) -> None:
    op.create_table(
        "submissions",
        sa.Column("id", sa.String(24), primary_key=True),
        sa.Column("token_hash", sa.String(64), nullable=False),  # sha256 of the secret link token
        sa.Column("owner_hash", sa.String(64), nullable=True),  # sha256 of the student's browser key
        sa.Column("student", sa.String(200), nullable=False, server_default=""),
        sa.Column("exercise", sa.String(100), nullable=True),  # as requested (None: the front matter's)
        sa.Column("graded_as", sa.String(100), nullable=True),  # the exercise id the worker graded against
        sa.Column("markdown", sa.Text, nullable=False),
        sa.Column("content_hash", sa.String(64), nullable=False),
        sa.Column("status", sa.String(16), nullable=False),  # queued, running, done, failed
        sa.Column("attempts", sa.Integer, nullable=False, server_default="0"),
        sa.Column("passed", sa.Boolean, nullable=True),
        sa.Column("first_wrong", sa.String(100), nullable=True),
        sa.Column("error", sa.Text, nullable=True),  # the student's input error (done) or why it failed
        sa.Column("report_json", sa.Text, nullable=True),
        sa.Column("report_html", sa.Text, nullable=True),  # the self-contained page (grade --html)
        sa.Column("report_fragment", sa.Text, nullable=True),  # the same report, to embed in a page
        sa.Column("cached", sa.Boolean, nullable=False, server_default=sa.false()),
        sa.Column("created_at", sa.Float, nullable=False),  # Unix seconds
        sa.Column("started_at", sa.Float, nullable=True),
        sa.Column("finished_at", sa.Float, nullable=True),
    )
    op.create_index("ix_submissions_status_created", "submissions", ["status", "created_at"])
    op.create_index("ix_submissions_content_hash", "submissions", ["content_hash"])
    op.create_index("ix_submissions_owner", "submissions", ["owner_hash"])


def _v2_identity(op: Operations) -> None:
    """Who submitted (the roster's student id, from a personal link or an LTI launch),
    whether after the deadline; personal links, student sessions and LTI 1.3's state
    (see :mod:`.identity` and :mod:`.lti`)."""
    with op.batch_alter_table("submissions") as batch:
        batch.add_column(sa.Column("student_id", sa.String(64), nullable=True))  # None: anonymous
        batch.add_column(sa.Column("late", sa.Boolean, nullable=True))  # None: no deadline
    op.create_index("ix_submissions_student", "submissions", ["student_id", "created_at"])
    op.create_table(
        "student_links",  # one secret personal link per roster student (sha256 of its token)
        sa.Column("student_id", sa.String(64), primary_key=True),
        sa.Column("link_hash", sa.String(64), nullable=False, unique=True),
        sa.Column("created_at", sa.Float, nullable=False),
    )
    op.create_table(
        "student_sessions",  # a student's login (personal link or LTI launch): sha256 of the cookie
        sa.Column("token_hash", sa.String(64), primary_key=True),
        sa.Column("student_id", sa.String(64), nullable=False),
        sa.Column("exercise", sa.String(100), nullable=False),
        sa.Column("expires_at", sa.Float, nullable=False),
    )
    op.create_table(
        "lti_states",  # OIDC login initiations waiting for their launch (single use)
        sa.Column("state_hash", sa.String(64), primary_key=True),
        sa.Column("nonce", sa.String(100), nullable=False),
        sa.Column("issuer", sa.String(500), nullable=False),
        sa.Column("client_id", sa.String(200), nullable=False),
        sa.Column("expires_at", sa.Float, nullable=False),
    )
    op.create_table(
        "lti_nonces",  # nonces of accepted launches: a replayed id_token is refused
        sa.Column("nonce", sa.String(100), primary_key=True),
        sa.Column("expires_at", sa.Float, nullable=False),
    )
    op.create_table(
        "lti_users",  # an LMS user bound to a roster student (by the roster's sub or email)
        sa.Column("issuer", sa.String(500), primary_key=True),
        sa.Column("sub", sa.String(255), primary_key=True),
        sa.Column("student_id", sa.String(64), nullable=False),
    )
    op.create_table(
        "lti_lineitems",  # where a student's score for an exercise goes (AGS)
        sa.Column("issuer", sa.String(500), primary_key=True),
        sa.Column("resource_link", sa.String(255), primary_key=True),
        sa.Column("student_id", sa.String(64), primary_key=True),
        sa.Column("client_id", sa.String(200), nullable=False),
        sa.Column("sub", sa.String(255), nullable=False),
        sa.Column("exercise", sa.String(100), nullable=False),
        sa.Column("lineitem", sa.String(1000), nullable=False),
    )


#: in order; version n is MIGRATIONS[n - 1]
MIGRATIONS = [_v1_submissions, _v2_identity]


def current_version(conn: sa.Connection) -> int:
    """The schema version of the database behind ``conn`` (0: empty)."""
    if not sa.inspect(conn).has_table("armdyn_schema"):
        return 0
    return int(conn.execute(sa.text("SELECT version FROM armdyn_schema")).scalar_one())


def upgrade(engine: sa.Engine) -> int:
    """Bring the schema up to date; returns the version now applied. Refuses a
    database written by a newer armdyn (a version this code does not know)."""
    with engine.begin() as conn:
        version = current_version(conn)
        if version > len(MIGRATIONS):
            raise RuntimeError(
                f"the database has schema version {version}, newer than this armdyn's {len(MIGRATIONS)}: upgrade armdyn"
            )
        op = Operations(MigrationContext.configure(conn))
        if version == 0:
            op.create_table("armdyn_schema", sa.Column("version", sa.Integer, nullable=False))
            conn.execute(sa.text("INSERT INTO armdyn_schema (version) VALUES (0)"))
        for n in range(version, len(MIGRATIONS)):
            MIGRATIONS[n](op)
            conn.execute(sa.text("UPDATE armdyn_schema SET version = :v"), {"v": n + 1})
        return len(MIGRATIONS)
