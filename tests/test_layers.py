"""The layering DESIGN.md draws: node/ and graph/ reach the network only through bus/'s seam."""

from __future__ import annotations

import ast

from tests.conftest import REPO

# what only bus/ may use: sockets, readiness waits, and the transports themselves
NETWORK_MODULES = {"socket", "select", "selectors", "asyncio", "ssl"}
TRANSPORT_MODULES = {"rosl.bus.multicast", "rosl.bus.inprocess"}


def imported_modules(path: str) -> set[str]:
    tree = ast.parse((REPO / path).read_text(), filename=path)
    found: set[str] = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module)
            found.update(f"{node.module}.{alias.name}" for alias in node.names)
    return found


def above_the_seam() -> list[str]:
    files = [*(REPO / "rosl" / "node").glob("*.py"), *(REPO / "rosl" / "graph").glob("*.py")]
    files.append(REPO / "rosl" / "executor.py")
    return sorted(str(f.relative_to(REPO)) for f in files)


def test_node_graph_and_the_executor_import_no_socket_select_or_transport_module() -> None:
    offenders = {}
    for path in above_the_seam():
        modules = imported_modules(path)
        bad = {m for m in modules if m.split(".")[0] in NETWORK_MODULES}
        bad |= {m for m in modules if any(m.startswith(t) for t in TRANSPORT_MODULES)}
        if bad:
            offenders[path] = sorted(bad)
    assert offenders == {}


def test_the_check_sees_the_files_it_guards() -> None:
    paths = above_the_seam()
    assert "rosl/node/participant.py" in paths
    assert "rosl/graph/announce.py" in paths
    assert "rosl/executor.py" in paths
    assert "rosl.bus.transport" in imported_modules("rosl/node/participant.py")
    assert "socket" in imported_modules("rosl/bus/multicast.py")  # the check would see one
