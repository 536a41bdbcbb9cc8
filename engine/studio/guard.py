"""Who may talk to the studio: the token, the Host header and the websocket's Origin.

The studio's page can run any graph and write the graph file, so its server answers only
the browser that was given its URL. :func:`guard` is an aiohttp middleware, put in front of
every route trame (through wslink) serves, HTTP and websocket alike:

- the request must carry the secret token, in the URL (``?token=...``, the link the studio
  prints) or in the cookie set on the first such request (the page's scripts, styles and
  websocket then need no token in their URLs); compared in constant time;
- its ``Host`` header must name the address the server listens on (a DNS-rebinding page,
  served from ``evil.example`` resolving to 127.0.0.1, sends ``Host: evil.example``);
- a websocket must come with an ``Origin`` that is the page's own (another site's page
  cannot open one to it), and any other request that has an ``Origin`` must match too.

Anything else gets HTTP 403 with a one-line reason and nothing of the page. Responses also
forbid framing (clickjacking) and referrers (the token stays out of other sites' logs).
"""

from __future__ import annotations

import hmac
import ipaddress
import secrets
from collections.abc import Iterable
from typing import Any

__all__ = ["Guard", "cookie_name", "new_token"]

SECURITY_HEADERS = {
    "X-Frame-Options": "DENY",
    "Content-Security-Policy": "frame-ancestors 'none'",
    "Referrer-Policy": "no-referrer",
    "X-Content-Type-Options": "nosniff",
    "Cache-Control": "no-store",
}


def new_token() -> str:
    """A fresh secret for the URL (256 bits, URL-safe)."""
    return secrets.token_urlsafe(32)


def cookie_name(port: int) -> str:
    """Cookies are shared by every port of a host: one name per port keeps two studios on
    one machine from overwriting each other's token."""
    return f"formgraph_studio_{port}"


def _split_host(host: str) -> tuple[str, int | None] | None:
    """``'127.0.0.1:8765'`` -> ``('127.0.0.1', 8765)``; ``'[::1]:80'`` -> ``('::1', 80)``."""
    host = host.strip().lower()
    if not host:
        return None
    if host.startswith("["):
        end = host.find("]")
        if end < 0:
            return None
        name, rest = host[1:end], host[end + 1 :]
        if rest and not rest.startswith(":"):
            return None
        try:  # brackets hold an IPv6 address, nothing else
            if ipaddress.ip_address(name).version != 6:
                return None
        except ValueError:
            return None
        port_text = rest[1:]
    else:
        name, sep, port_text = host.rpartition(":")
        if not sep:
            name, port_text = host, ""
        elif ":" in name:  # an unbracketed IPv6 address: not a valid Host header
            return None
    if port_text and not port_text.isdigit():
        return None
    return name, int(port_text) if port_text else None


def _is_loopback(name: str) -> bool:
    try:
        return ipaddress.ip_address(name).is_loopback
    except ValueError:
        return False


class Guard:
    """The checks of one running studio (an aiohttp middleware: ``app.middlewares.append``).

    Parameters
    ----------
    token : str
        The secret every request must carry.
    names : iterable of str
        Host names the page may be reached by besides the address the request came in on
        (``localhost`` is added when that address is a loopback one).
    """

    def __init__(self, token: str, names: Iterable[str] = ()):
        self.token = token
        self.names = {n.lower().strip("[]") for n in names if n}
        self.refused = 0  # requests answered 403, for tests and the log

    # the checks, apart from aiohttp so that they can be tested on plain values
    def problem(
        self,
        host: str | None,
        local: tuple[str, int] | None,
        origin: str | None,
        websocket: bool,
        supplied: str | None,
    ) -> str | None:
        """Why a request must be refused, or None when it may pass."""
        parsed = _split_host(host or "")
        if parsed is None:
            return "a Host header is required"
        name, port = parsed
        allowed = set(self.names)
        if local is not None:
            address, local_port = local[0].lower(), local[1]
            if address.startswith("::ffff:"):  # IPv4 mapped into an IPv6 socket
                address = address[7:]
            allowed.add(address)
            if _is_loopback(address):
                allowed.update(("localhost", "127.0.0.1", "::1"))
            if port != local_port:
                return f"the Host header {host!r} does not name this server"
        if name not in allowed:
            return f"the Host header {host!r} does not name this server"
        if origin is not None or websocket:
            own = {f"http://{host.strip().lower()}", f"https://{host.strip().lower()}"}
            if origin is None or origin.strip().lower() not in own:
                return f"the Origin {origin!r} is not this page's"
        if not supplied or not hmac.compare_digest(supplied.encode(), self.token.encode()):
            return "a valid token is required (open the URL the studio printed)"
        return None

    @property
    def middleware(self) -> Any:
        from aiohttp import hdrs, web

        @web.middleware
        async def guard(request: web.Request, handler: Any) -> web.StreamResponse:
            sockname = request.transport.get_extra_info("sockname") if request.transport else None
            local = (str(sockname[0]), int(sockname[1])) if sockname else None
            port = local[1] if local else 0
            cookie = cookie_name(port)
            from_url = request.query.get("token")
            supplied = from_url or request.cookies.get(cookie)
            websocket = request.headers.get(hdrs.UPGRADE, "").lower() == "websocket"
            why = self.problem(
                request.headers.get(hdrs.HOST),
                local,
                request.headers.get(hdrs.ORIGIN),
                websocket,
                supplied,
            )
            if why is not None:
                self.refused += 1
                return web.Response(status=403, text=f"403 forbidden: {why}\n")
            try:
                response = await handler(request)
            except web.HTTPException as exc:  # a redirect ("/" -> "index.html") carries it
                response = exc
            if not websocket:
                for k, v in SECURITY_HEADERS.items():
                    response.headers.setdefault(k, v)
                if from_url and request.cookies.get(cookie) != from_url:
                    response.set_cookie(
                        cookie, from_url, httponly=True, samesite="Strict", path="/"
                    )
            if isinstance(response, web.HTTPException):
                raise response
            return response

        return guard
