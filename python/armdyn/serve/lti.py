"""LTI 1.3, the tool's side: Moodle, Canvas (any LTI 1.3 platform) launch armdyn.

The flow (IMS LTI 1.3 and its Security Framework):

1. **Login initiation** ``/lti/login`` (GET or POST from the platform: ``iss``,
   ``login_hint``, ``target_link_uri``, ``lti_message_hint``, ``client_id``): a fresh
   ``state`` and ``nonce`` are stored (single use, 10 minutes), ``state`` also in a
   cookie of this browser, and the browser goes to the platform's OIDC authorization
   endpoint.
2. **Launch** ``/lti/launch`` (the platform POSTs ``id_token`` and ``state``): the
   state must be this browser's and unused; the ``id_token`` (a JWT) must be signed
   RS256 by a key of the platform's JWKS (fetched from its ``key_set_url``), issued by
   the platform for this tool (``iss``, ``aud``/``azp`` = client id), current (``exp``,
   ``iat``, a minute of leeway), from a registered deployment, and carry the nonce of
   that state, never seen before. Anything else is refused (400/401/403) and logged.
3. A **resource link** launch maps the LMS user to a roster student (bound before, or
   the roster's ``lti_sub``, or the roster's ``email``), opens their session on their
   variant (:mod:`.identity`) and remembers the line item (AGS) their score goes to.
   An instructor's launch opens the instructor page.
4. **Deep linking** (an instructor adding armdyn to a course): a page to choose the
   exercise; the choice goes back to the platform as a signed ``LtiDeepLinkingResponse``
   JWT holding one ``ltiResourceLink`` (custom parameter ``exercise``, a line item).
5. **Score passback** (AGS): when a submission of a launched student is graded, the
   score the gradebook's policy counts is POSTed to the line item's ``/scores``, with
   an access token got by the client-credentials grant and a JWT assertion signed with
   the tool's key (published at ``/lti/jwks``).

JWTs are made and checked by PyJWT (``pip install 'armdyn[serve]'``); the platforms and
the tool's key come from the YAML file of ``armdyn serve --lti`` (see docs/serve.md).
"""

from __future__ import annotations

import json
import logging
import os
import secrets
import threading
import time
import urllib.parse
import urllib.request
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field

import sqlalchemy as sa

from ..errors import ModelError
from . import security
from .identity import Refused

log = logging.getLogger("armdyn.serve")

LTI = "https://purl.imsglobal.org/spec/lti/claim/"
DL = "https://purl.imsglobal.org/spec/lti-dl/claim/"
AGS_ENDPOINT = "https://purl.imsglobal.org/spec/lti-ags/claim/endpoint"
SCORE_SCOPE = "https://purl.imsglobal.org/spec/lti-ags/scope/score"
INSTRUCTOR_ROLES = ("#Instructor", "#Administrator", "#ContentDeveloper", "#TeachingAssistant")
LEEWAY = 60  # seconds of clock skew allowed on exp and iat
STATE_SECONDS = 600  # a login initiation must end in its launch within this
NONCE_SECONDS = 86400  # a nonce is remembered this long (far past any id_token's exp)
LAUNCH_SESSION_SECONDS = 12 * 3600
HTTP_TIMEOUT = 10.0  # seconds, each request to the platform
ASSIGNED = "assigned"  # the custom parameter for "each student their own variant"

_meta = sa.MetaData()
STATES = sa.Table(
    "lti_states",
    _meta,
    sa.Column("state_hash", sa.String(64), primary_key=True),
    sa.Column("nonce", sa.String(100)),
    sa.Column("issuer", sa.String(500)),
    sa.Column("client_id", sa.String(200)),
    sa.Column("expires_at", sa.Float),
)
NONCES = sa.Table(
    "lti_nonces", _meta, sa.Column("nonce", sa.String(100), primary_key=True), sa.Column("expires_at", sa.Float)
)
USERS = sa.Table(
    "lti_users",
    _meta,
    sa.Column("issuer", sa.String(500), primary_key=True),
    sa.Column("sub", sa.String(255), primary_key=True),
    sa.Column("student_id", sa.String(64)),
)
LINEITEMS = sa.Table(
    "lti_lineitems",
    _meta,
    sa.Column("issuer", sa.String(500), primary_key=True),
    sa.Column("resource_link", sa.String(255), primary_key=True),
    sa.Column("student_id", sa.String(64), primary_key=True),
    sa.Column("client_id", sa.String(200)),
    sa.Column("sub", sa.String(255)),
    sa.Column("exercise", sa.String(100)),
    sa.Column("lineitem", sa.String(1000)),
)


@dataclass(frozen=True)
class Platform:
    """One registration of armdyn in an LMS (what the LMS shows after adding the tool)."""

    issuer: str
    client_id: str
    deployment_ids: tuple[str, ...]
    auth_login_url: str  # the platform's OIDC authorization endpoint
    auth_token_url: str  # its OAuth 2 token endpoint (AGS)
    key_set_url: str  # its public keys (JWKS)
    auth_audience: str = ""  # the aud of the token request's assertion (default: auth_token_url)


@dataclass
class Tool:
    """armdyn as an LTI 1.3 tool: its address, its RSA key, the platforms it trusts."""

    url: str
    private_key: object  # cryptography's RSAPrivateKey
    platforms: list[Platform]
    kid: str = ""
    _jwks: dict = field(default_factory=dict)
    _tokens: dict = field(default_factory=dict)
    _lock: threading.Lock = field(default_factory=threading.Lock)
    passbacks: ThreadPoolExecutor = field(default_factory=lambda: ThreadPoolExecutor(1, thread_name_prefix="lti-ags"))

    def __post_init__(self):
        import hashlib

        n = self.private_key.public_key().public_numbers().n
        self.kid = self.kid or hashlib.sha256(n.to_bytes((n.bit_length() + 7) // 8, "big")).hexdigest()[:16]
        self.url = self.url.rstrip("/")

    @classmethod
    def load(cls, path: str) -> Tool:
        """The ``--lti`` YAML file: ``url``, ``key`` (PEM file of the tool's RSA key,
        relative to the YAML; made, mode 600, when it does not exist) and ``platforms``."""
        import yaml

        try:
            with open(path, encoding="utf-8") as f:
                conf = yaml.safe_load(f)
        except (OSError, yaml.YAMLError) as err:
            raise ModelError(f"cannot read the LTI configuration ({err})", source=path) from None
        if not isinstance(conf, dict) or not conf.get("url") or not isinstance(conf.get("platforms"), list):
            raise ModelError("the LTI configuration needs url:, key: and a list of platforms:", source=path)
        if not str(conf["url"]).startswith(("https://", "http://127.0.0.1", "http://localhost")):
            raise ModelError("url: must be https:// (LMSs launch tools over TLS only)", source=path)
        key_path = os.path.join(os.path.dirname(os.path.abspath(path)), str(conf.get("key") or "lti-key.pem"))
        platforms = []
        for n, p in enumerate(conf["platforms"], start=1):
            need = ("issuer", "client_id", "deployment_ids", "auth_login_url", "auth_token_url", "key_set_url")
            missing = [k for k in need if not isinstance(p, dict) or not p.get(k)]
            if missing:
                raise ModelError(f"platform {n} lacks {', '.join(missing)}", source=path)
            ids = p["deployment_ids"] if isinstance(p["deployment_ids"], list) else [p["deployment_ids"]]
            platforms.append(
                Platform(
                    str(p["issuer"]),
                    str(p["client_id"]),
                    tuple(str(d) for d in ids),
                    str(p["auth_login_url"]),
                    str(p["auth_token_url"]),
                    str(p["key_set_url"]),
                    str(p.get("auth_audience") or ""),
                )
            )
        return cls(str(conf["url"]), load_or_make_key(key_path), platforms)

    def platform(self, issuer: str, client_id: str | None) -> Platform | None:
        found = [p for p in self.platforms if p.issuer == issuer and (client_id is None or p.client_id == client_id)]
        return found[0] if len(found) == 1 else None

    def jwks(self) -> dict:
        """The tool's public key set (what platforms verify its JWTs with)."""
        from jwt.algorithms import RSAAlgorithm

        jwk = RSAAlgorithm.to_jwk(self.private_key.public_key(), as_dict=True)
        jwk.update(kid=self.kid, alg="RS256", use="sig")
        return {"keys": [jwk]}

    def sign(self, claims: dict) -> str:
        import jwt

        return jwt.encode(claims, self.private_key, algorithm="RS256", headers={"kid": self.kid})

    def platform_key(self, platform: Platform, token: str):
        """The platform's public key that signed ``token`` (its JWKS, cached; fetched
        again for a key id it does not hold: platforms rotate keys)."""
        import jwt

        with self._lock:
            client = self._jwks.get(platform.key_set_url)
            if client is None:
                client = jwt.PyJWKClient(platform.key_set_url, cache_keys=True, lifespan=3600, timeout=HTTP_TIMEOUT)
                self._jwks[platform.key_set_url] = client
        return client.get_signing_key_from_jwt(token).key

    # -- AGS
    def access_token(self, platform: Platform) -> str:
        """An AGS access token (client credentials with a signed JWT assertion), cached."""
        key = (platform.issuer, platform.client_id)
        held = self._tokens.get(key)
        if held and held[1] > time.time() + 30:
            return held[0]
        now = int(time.time())
        assertion = self.sign(
            {
                "iss": platform.client_id,
                "sub": platform.client_id,
                "aud": platform.auth_audience or platform.auth_token_url,
                "iat": now,
                "exp": now + 300,
                "jti": secrets.token_urlsafe(16),
            }
        )
        body = urllib.parse.urlencode(
            {
                "grant_type": "client_credentials",
                "client_assertion_type": "urn:ietf:params:oauth:client-assertion-type:jwt-bearer",
                "client_assertion": assertion,
                "scope": SCORE_SCOPE,
            }
        ).encode()
        reply = _post(platform.auth_token_url, body, {"content-type": "application/x-www-form-urlencoded"})
        token = reply.get("access_token")
        if not token:
            raise ValueError(f"the platform's token endpoint gave no access_token ({str(reply)[:200]})")
        self._tokens[key] = (token, time.time() + float(reply.get("expires_in", 3600)))
        return token

    def post_score(self, platform: Platform, lineitem: str, sub: str, given: float, maximum: float, comment: str):
        """POST one score to ``lineitem``'s scores (AGS 2.0)."""
        parts = urllib.parse.urlsplit(lineitem)
        scores = urllib.parse.urlunsplit(parts._replace(path=parts.path.rstrip("/") + "/scores"))
        score = {
            "userId": sub,
            "scoreGiven": given,
            "scoreMaximum": maximum,
            "comment": comment,
            "activityProgress": "Completed",
            "gradingProgress": "FullyGraded",
            "timestamp": time.strftime("%Y-%m-%dT%H:%M:%S", time.gmtime()) + f".{int(time.time() % 1 * 1000):03d}Z",
        }
        headers = {
            "content-type": "application/vnd.ims.lis.v1.score+json",
            "authorization": f"Bearer {self.access_token(platform)}",
        }
        _post(scores, json.dumps(score).encode(), headers)


def load_or_make_key(path: str):
    """The tool's RSA private key from ``path``; a new 2048-bit one is written there
    (mode 600) when the file does not exist."""
    from cryptography.hazmat.primitives import serialization
    from cryptography.hazmat.primitives.asymmetric import rsa

    if not os.path.exists(path):
        key = rsa.generate_private_key(public_exponent=65537, key_size=2048)
        pem = key.private_bytes(
            serialization.Encoding.PEM, serialization.PrivateFormat.PKCS8, serialization.NoEncryption()
        )
        fd = os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
        with os.fdopen(fd, "wb") as f:
            f.write(pem)
        return key
    try:
        with open(path, "rb") as f:
            key = serialization.load_pem_private_key(f.read(), password=None)
    except (OSError, ValueError) as err:
        raise ModelError(f"not the tool's RSA private key in PEM ({err})", source=path) from None
    if not isinstance(key, rsa.RSAPrivateKey):
        raise ModelError("the tool's key must be an RSA key (LTI 1.3 signs with RS256)", source=path)
    return key


def _post(url: str, body: bytes, headers: dict) -> dict:
    req = urllib.request.Request(url, data=body, method="POST", headers=headers)
    with urllib.request.urlopen(req, timeout=HTTP_TIMEOUT) as r:
        raw = r.read()
    try:
        return json.loads(raw) if raw else {}
    except ValueError:
        return {}


# -- state, nonces, users, line items (tables of migration 2)


class Ledger:
    """The launches' memory in the database: so it holds across a restart and, with
    PostgreSQL, across servers."""

    def __init__(self, engine: sa.Engine):
        self.engine = engine

    def new_state(self, platform: Platform) -> tuple[str, str]:
        """A fresh (state, nonce) for a login initiation."""
        state, nonce = secrets.token_urlsafe(32), secrets.token_urlsafe(32)
        now = time.time()
        with self.engine.begin() as conn:
            conn.execute(STATES.delete().where(STATES.c.expires_at <= now))
            conn.execute(
                STATES.insert().values(
                    state_hash=security.digest(state),
                    nonce=nonce,
                    issuer=platform.issuer,
                    client_id=platform.client_id,
                    expires_at=now + STATE_SECONDS,
                )
            )
        return state, nonce

    def take_state(self, state: str) -> dict | None:
        """The state's row, deleted (a state serves one launch); None: unknown or expired."""
        with self.engine.begin() as conn:
            row = conn.execute(STATES.select().where(STATES.c.state_hash == security.digest(state))).mappings().first()
            if row is None:
                return None
            conn.execute(STATES.delete().where(STATES.c.state_hash == row["state_hash"]))
        return dict(row) if row["expires_at"] > time.time() else None

    def use_nonce(self, nonce: str) -> bool:
        """Record ``nonce`` as used; False when it was used before (a replay)."""
        now = time.time()
        try:
            with self.engine.begin() as conn:
                conn.execute(NONCES.delete().where(NONCES.c.expires_at <= now))
                conn.execute(NONCES.insert().values(nonce=nonce, expires_at=now + NONCE_SECONDS))
        except sa.exc.IntegrityError:
            return False
        return True

    def bound_student(self, issuer: str, sub: str) -> str | None:
        with self.engine.connect() as conn:
            return conn.execute(
                sa.select(USERS.c.student_id).where(USERS.c.issuer == issuer, USERS.c.sub == sub)
            ).scalar_one_or_none()

    def bind(self, issuer: str, sub: str, student_id: str) -> None:
        with self.engine.begin() as conn:
            conn.execute(USERS.delete().where(USERS.c.issuer == issuer, USERS.c.sub == sub))
            conn.execute(USERS.insert().values(issuer=issuer, sub=sub, student_id=student_id))

    def remember_lineitem(self, **row) -> None:
        with self.engine.begin() as conn:
            conn.execute(
                LINEITEMS.delete().where(
                    LINEITEMS.c.issuer == row["issuer"],
                    LINEITEMS.c.resource_link == row["resource_link"],
                    LINEITEMS.c.student_id == row["student_id"],
                )
            )
            conn.execute(LINEITEMS.insert().values(**row))

    def lineitems(self, student_id: str, exercise: str) -> list[dict]:
        with self.engine.connect() as conn:
            rows = conn.execute(
                LINEITEMS.select().where(LINEITEMS.c.student_id == student_id, LINEITEMS.c.exercise == exercise)
            ).mappings()
            return [dict(r) for r in rows]


# -- the launch


def verify_launch(tool: Tool, ledger: Ledger, id_token: str, state_row: dict) -> dict:
    """The claims of a launch's ``id_token``, checked (see the module's docstring);
    every failure is a :class:`Refused` naming what failed."""
    import jwt

    platform = tool.platform(state_row["issuer"], state_row["client_id"])
    if platform is None:
        raise Refused(403, "this platform is no longer registered", f"launch for unregistered {state_row['issuer']}")
    try:
        header = jwt.get_unverified_header(id_token)
    except jwt.PyJWTError as err:
        raise Refused(400, "the id_token is not a JWT", f"launch with a malformed id_token ({err})") from None
    if header.get("alg") != "RS256":
        raise Refused(401, "the id_token must be signed RS256", f"launch with alg {str(header.get('alg'))[:20]}")
    try:
        key = tool.platform_key(platform, id_token)
        claims = jwt.decode(
            id_token,
            key,
            algorithms=["RS256"],
            audience=platform.client_id,
            issuer=platform.issuer,
            leeway=LEEWAY,
            options={"require": ["exp", "iat", "iss", "aud", "sub", "nonce"]},
        )
    except jwt.ExpiredSignatureError:
        raise Refused(
            401, "the launch has expired: start it again from the LMS", "launch with an expired id_token"
        ) from None
    except jwt.InvalidAudienceError:
        raise Refused(403, "the launch is meant for another tool", "launch with a wrong audience") from None
    except jwt.InvalidIssuerError:
        raise Refused(403, "the launch comes from another platform", "launch with a wrong issuer") from None
    except jwt.PyJWKClientConnectionError as err:
        raise Refused(
            503, "the platform's keys could not be fetched: try again", f"platform key set unreachable ({err})"
        ) from None
    except jwt.PyJWKClientError as err:
        raise Refused(401, "the launch's key is not the platform's", f"launch signing key not found ({err})") from None
    except jwt.PyJWTError as err:
        name = type(err).__name__
        raise Refused(401, f"the launch's token is not valid ({name})", f"launch refused: {name}: {err}") from None
    aud = claims["aud"]
    if isinstance(aud, list) and len(aud) > 1 and claims.get("azp") != platform.client_id:
        raise Refused(403, "the launch is meant for another tool", "launch with several audiences and a wrong azp")
    if claims["nonce"] != state_row["nonce"]:
        raise Refused(403, "the launch does not belong to its login", "launch whose nonce is not its state's")
    if not ledger.use_nonce(claims["nonce"]):
        raise Refused(403, "this launch was used before", f"replayed launch nonce from {platform.issuer}")
    deployment = claims.get(LTI + "deployment_id")
    if deployment not in platform.deployment_ids:
        raise Refused(
            403,
            "this deployment of the tool is not registered",
            f"launch from unknown deployment {str(deployment)[:64]}",
        )
    if claims.get(LTI + "version") != "1.3.0":
        raise Refused(400, "only LTI 1.3.0 launches are understood", "launch of another LTI version")
    return claims


def is_instructor(claims: dict) -> bool:
    return any(str(r).endswith(INSTRUCTOR_ROLES) for r in claims.get(LTI + "roles") or [])


def student_for(settings, ledger: Ledger, claims: dict):
    """The roster student of the launching user: bound before, else the roster's
    ``lti_sub``, else its ``email`` (then bound to the user's sub)."""
    sub, issuer = str(claims["sub"]), claims["iss"]
    roster = settings.roster or {}
    sid = ledger.bound_student(issuer, sub)
    if sid in roster:
        return roster[sid]
    email = str(claims.get("email") or "").lower()
    found = [s for s in roster.values() if s.lti_sub == sub] or [
        s for s in roster.values() if email and s.email == email
    ]
    if not found:
        raise Refused(
            403,
            "you are not on this course's roster: ask your instructor to add you (by your email in the LMS)",
            f"LTI user {sub[:64]} ({email[:80] or 'no email'}) of {issuer} is not on the roster",
        )
    ledger.bind(issuer, sub, found[0].id)
    return found[0]


def exercise_for(settings, claims: dict, student) -> str:
    """The exercise of a resource link: its custom ``exercise`` when that is a served
    exercise shared by the class (not a variant), else the student's own variant."""
    wanted = (claims.get(LTI + "custom") or {}).get("exercise")
    chosen = settings.exercises.get(wanted) if isinstance(wanted, str) else None
    return chosen.id if chosen is not None and not chosen.variant else student.variant
