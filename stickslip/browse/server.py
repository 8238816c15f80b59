"""Serve a built site read only on the loopback address (Python's ``http.server``).

The handler is the standard library's :class:`http.server.SimpleHTTPRequestHandler` on one folder: it answers
GET and HEAD with the folder's files and nothing else (any other method gets 501, a path outside the folder 404),
so nothing a browser sends can change a file. It listens on 127.0.0.1 only.
"""

import functools
import http.server
import threading

__all__ = ["HOST", "ReadOnlyHandler", "start", "serve"]

#: The address served: the loopback interface, never the network.
HOST = "127.0.0.1"


class ReadOnlyHandler(http.server.SimpleHTTPRequestHandler):
    """GET and HEAD of the site's files; the request log goes to ``log`` (None: nowhere)."""

    log = None

    def end_headers(self):
        self.send_header("Cache-Control", "no-store")  # a rebuilt site shows at once
        super().end_headers()

    def log_message(self, format, *args):  # noqa: A002 (the base class's name)
        if self.log is not None:
            self.log(f"{self.address_string()} {format % args}")


def start(directory, port=0, log=None):
    """Start serving ``directory`` in a background thread.

    Parameters
    ----------
    directory : str or os.PathLike
        The built site.
    port : int, optional
        0: a free port that the system picks.
    log : Callable[[str], None], optional
        Receives one line per request.

    Returns
    -------
    http.server.ThreadingHTTPServer
        Serving; its URL is ``http://127.0.0.1:{server.server_port}/``; ``server.shutdown()`` stops it.
    """
    handler = functools.partial(type("Handler", (ReadOnlyHandler,), {"log": staticmethod(log) if log else None}),
                                directory=str(directory))
    server = http.server.ThreadingHTTPServer((HOST, port), handler)
    threading.Thread(target=server.serve_forever, daemon=True, name="stickslip-browse").start()
    return server



def serve(directory, port=0, log=None, ready=None):
    """Serve ``directory`` until Ctrl-C or SIGTERM (:func:`start`, then wait); the server is closed after.

    ``ready`` (optional) receives the server once it listens (its port: ``server.server_port``).
    """
    server = start(directory, port, log)
    try:
        if ready is not None:
            ready(server)
        threading.Event().wait()
    finally:
        server.shutdown()
        server.server_close()
