"""A tiny LTI 1.3 platform for tests/test_serve_lti.py: an LMS as armdyn sees it.

It holds its own RSA key and serves, on 127.0.0.1, its key set (``/jwks``), an OAuth 2
token endpoint (``/token``: checks the tool's client assertion against the tool's
published key set, then hands out a bearer token) and an AGS line item (``/lineitems/7``:
records every score POSTed to ``/lineitems/7/scores`` with the token it came with). It
writes id_tokens as Moodle or Canvas would (claims of the LTI 1.3 specification), each
field open to a test's forgery.
"""

from __future__ import annotations

import json
import secrets
import threading
import time
import urllib.parse
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer

import jwt
from cryptography.hazmat.primitives.asymmetric import rsa
from jwt.algorithms import RSAAlgorithm

LTI = "https://purl.imsglobal.org/spec/lti/claim/"
DL = "https://purl.imsglobal.org/spec/lti-dl/claim/"
AGS = "https://purl.imsglobal.org/spec/lti-ags/claim/endpoint"
SCORE_SCOPE = "https://purl.imsglobal.org/spec/lti-ags/scope/score"
CLIENT_ID = "armdyn-client-17"
DEPLOYMENT = "deployment-3"
LEARNER = "http://purl.imsglobal.org/vocab/lis/v2/membership#Learner"
INSTRUCTOR = "http://purl.imsglobal.org/vocab/lis/v2/membership#Instructor"
TOOL_URL = "https://armdyn.test"


def new_key():
    return rsa.generate_private_key(public_exponent=65537, key_size=2048)


class Platform:
    """The LMS: start() serves it; id_token() writes a launch."""

    def __init__(self):
        self.key = new_key()
        self.kid = "platform-key-1"
        self.tool_jwks: dict | None = None  # the tool's /lti/jwks, given by the test
        self.tokens: dict[str, float] = {}  # bearer tokens handed out
        self.assertions: list[dict] = []  # verified client assertions
        self.scores: list[tuple[str, str, dict]] = []  # (path, authorization, score)
        self.refusals: list[str] = []
        self.server: ThreadingHTTPServer | None = None

    # -- served
    def start(self) -> Platform:
        platform = self

        class Handler(BaseHTTPRequestHandler):
            def log_message(self, *args):
                pass

            def _send(self, status: int, body: dict):
                raw = json.dumps(body).encode()
                self.send_response(status)
                self.send_header("content-type", "application/json")
                self.send_header("content-length", str(len(raw)))
                self.end_headers()
                self.wfile.write(raw)

            def do_GET(self):
                if self.path == "/jwks":
                    return self._send(200, platform.jwks())
                return self._send(404, {"error": "no such page"})

            def do_POST(self):
                body = self.rfile.read(int(self.headers.get("content-length", "0")))
                if self.path == "/token":
                    return self._send(*platform.token_request(urllib.parse.parse_qs(body.decode())))
                if self.path == "/lineitems/7/scores":
                    auth = self.headers.get("authorization", "")
                    if auth[7:] not in platform.tokens or self.headers.get("content-type") != (
                        "application/vnd.ims.lis.v1.score+json"
                    ):
                        platform.refusals.append("score without a valid token or content type")
                        return self._send(401, {"error": "unauthorized"})
                    platform.scores.append((self.path, auth, json.loads(body)))
                    return self._send(200, {})
                return self._send(404, {"error": "no such endpoint"})

        self.server = ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        threading.Thread(target=self.server.serve_forever, daemon=True).start()
        return self

    def stop(self) -> None:
        if self.server is not None:
            self.server.shutdown()
            self.server.server_close()

    @property
    def base(self) -> str:
        return f"http://127.0.0.1:{self.server.server_address[1]}"

    @property
    def issuer(self) -> str:
        return self.base  # a platform's issuer is its address, as Moodle's is

    def jwks(self) -> dict:
        jwk = RSAAlgorithm.to_jwk(self.key.public_key(), as_dict=True)
        jwk.update(kid=self.kid, alg="RS256", use="sig")
        return {"keys": [jwk]}

    def registration(self) -> dict:
        """What the instructor copies from the LMS into armdyn's --lti file."""
        return {
            "issuer": self.issuer,
            "client_id": CLIENT_ID,
            "deployment_ids": [DEPLOYMENT],
            "auth_login_url": self.base + "/auth",
            "auth_token_url": self.base + "/token",
            "key_set_url": self.base + "/jwks",
        }

    def token_request(self, form: dict) -> tuple[int, dict]:
        """OAuth 2 client credentials with a JWT assertion, checked with the tool's keys."""
        one = {k: v[0] for k, v in form.items()}
        if one.get("grant_type") != "client_credentials" or one.get("scope") != SCORE_SCOPE:
            self.refusals.append(f"token request: {one.get('grant_type')} {one.get('scope')}")
            return 400, {"error": "invalid_request"}
        try:
            kid = jwt.get_unverified_header(one["client_assertion"])["kid"]
            key = jwt.PyJWKSet.from_dict(self.tool_jwks)[kid].key
            claims = jwt.decode(
                one["client_assertion"],
                key,
                algorithms=["RS256"],
                audience=self.base + "/token",
                issuer=CLIENT_ID,
                options={"require": ["exp", "iat", "jti", "sub"]},
            )
        except (jwt.PyJWTError, KeyError, TypeError) as err:
            self.refusals.append(f"client assertion: {err}")
            return 401, {"error": "invalid_client"}
        if claims["sub"] != CLIENT_ID:
            return 401, {"error": "invalid_client"}
        self.assertions.append(claims)
        token = secrets.token_urlsafe(16)
        self.tokens[token] = time.time() + 3600
        return 200, {"access_token": token, "token_type": "Bearer", "expires_in": 3600, "scope": SCORE_SCOPE}

    # -- launches
    def claims(self, nonce: str, /, **change) -> dict:
        now = int(time.time())
        out = {
            "iss": self.issuer,
            "aud": CLIENT_ID,
            "sub": "lms-user-41",
            "iat": now,
            "exp": now + 300,
            "nonce": nonce,
            "email": "ada@example.edu",
            "name": "Ada L.",
            LTI + "message_type": "LtiResourceLinkRequest",
            LTI + "version": "1.3.0",
            LTI + "deployment_id": DEPLOYMENT,
            LTI + "target_link_uri": TOOL_URL + "/lti/launch",
            LTI + "resource_link": {"id": "resource-link-9"},
            LTI + "roles": [LEARNER],
            AGS: {"scope": [SCORE_SCOPE], "lineitem": self.base + "/lineitems/7"},
        }
        out.update(change)
        return {k: v for k, v in out.items() if v is not None}

    def id_token(self, claims: dict, key=None, kid: str | None = None) -> str:
        return jwt.encode(claims, key or self.key, algorithm="RS256", headers={"kid": kid or self.kid})
