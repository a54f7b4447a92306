"""The terminal UIs of `monitor` and `teleop` (Textual, the `tui` extra; imported by those commands
only). Both show the dashboard (roverlink.dashboard); teleop adds the keys of roverlink.teleop.
Tested headless with Textual's `App.run_test()` and a pilot pressing keys.
"""

from __future__ import annotations

from typing import Any

from host_sdk.extras import require
from roverlink.dashboard import Dashboard, link_lines, motion_lines, sensor_lines, state_lines
from roverlink.teleop import KEYS, OVERRIDE_KEYS, TeleopController

_textual_app = require("textual.app", "tui", "the terminal view")
_widgets = require("textual.widgets", "tui", "the terminal view")
App: Any = _textual_app.App
Static: Any = _widgets.Static
Header: Any = _widgets.Header
Footer: Any = _widgets.Footer
Binding: Any = require("textual.binding", "tui", "the terminal view").Binding

CSS = """
Static { border: round $accent; padding: 0 1; }
#log { height: 1fr; }
"""


class DashboardApp(App):  # type: ignore[misc]
    """The monitor: read-only, refreshed `hz` times a second."""

    CSS = CSS
    BINDINGS = [("q", "quit", "quit")]  # noqa: RUF012 (Textual's class attribute)

    def __init__(self, dashboard: Dashboard, hz: float = 5.0, on_refresh: Any = None) -> None:
        super().__init__()
        self.dashboard = dashboard
        self.hz = hz
        self.on_refresh = on_refresh
        self.title = "roverlink monitor"

    def compose(self) -> Any:
        yield Header()
        yield Static(id="state")
        yield Static(id="motion")
        if self.dashboard.sensors is not None:
            yield Static(id="sensors")
        yield Static(id="link")
        yield Static(id="log")
        yield Footer()

    def on_mount(self) -> None:
        self.refresh_view()
        self.set_interval(1 / self.hz, self.refresh_view)

    def refresh_view(self) -> None:
        self.dashboard.poll()
        if self.on_refresh is not None:
            self.on_refresh()
        s = self.dashboard.snapshot()
        self.query_one("#state").update("\n".join(state_lines(s)))
        self.query_one("#motion").update("\n".join(motion_lines(s)) or "no FEEDBACK yet")
        if s.sensors is not None:
            self.query_one("#sensors").update("sensors\n" + "\n".join(sensor_lines(s)))
        self.query_one("#link").update("link\n" + "\n".join(link_lines(s)))
        self.query_one("#log").update("log\n" + ("\n".join(s.logs) or "(none)"))


class TeleopApp(DashboardApp):
    """Keyboard driving over the dashboard; the controller's own thread sends the commands, so
    a busy UI does not delay them."""

    # Priority bindings: the arrow keys would otherwise scroll before the app sees them.
    BINDINGS = [  # noqa: RUF012 (Textual's class attribute)
        ("q", "quit", "quit"),
        *(
            Binding(key, f"drive('{key}')", show=False, priority=True)
            for key in (*KEYS, *OVERRIDE_KEYS)
            if len(key) > 1 or key.isalpha()
        ),
    ]

    def __init__(self, dashboard: Dashboard, controller: TeleopController) -> None:
        super().__init__(dashboard)
        self.controller = controller
        self.title = "roverlink teleop"
        self.sub_title = controller.message

    def on_mount(self) -> None:
        super().on_mount()
        self.controller.start()

    def on_unmount(self) -> None:
        self.controller.close()

    def action_drive(self, key: str) -> None:
        self.controller.key(key)
        self.sub_title = self.controller.status

    def refresh_view(self) -> None:
        self.dashboard.setpoint = self.controller.setpoint
        super().refresh_view()
        self.sub_title = self.controller.status
