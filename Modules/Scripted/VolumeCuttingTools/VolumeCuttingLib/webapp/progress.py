"""A trainee's progress in the web application: learning curves of the score and key metrics, from the records.

The Progress panel lists the trainees of the records database
(``--records URL``, default: the user's SQLite file, see
``VolumeCuttingLib.records.database``), and for the one chosen draws one
small chart per value over the trainee's sessions in time order: the score
and the metrics picked (by default those of ``KEY_METRICS`` the trainee has).
The charts are SVG made here; each point carries its session number and value
(``data-number``, ``data-value``) so that a test reads what is drawn. A
database that cannot be opened is said in the panel; the drilling goes on.
The records are opened when the panel is first expanded.
"""

from __future__ import annotations

import html as html_text
import math

from trame.widgets import html
from trame.widgets import vuetify3 as v3

from ..records import database

#: Metrics a program watches first, shown beside the score when the trainee has them.
KEY_METRICS = ("final.dice", "safety.contacts.FacialNerve", "efficiency.path_length_mm", "efficiency.time_s",
               "visibility.hidden_removed_mm3")
DEFAULT_METRIC_COUNT = 2
CHART_WIDTH, CHART_HEIGHT = 340, 120
MARGIN_LEFT, MARGIN_RIGHT, MARGIN_TOP, MARGIN_BOTTOM = 44, 10, 18, 22


def chart_points(values: list, width: float = CHART_WIDTH, height: float = CHART_HEIGHT) -> list:
    """(session number, value, x, y) in the chart's pixels for the sessions that measured the value.

    Sessions spread evenly from left to right by number; the value axis runs
    from the smallest to the largest value (a flat curve sits in the middle).
    """
    measured = [(number, value) for number, value in values if value is not None and math.isfinite(value)]
    if not measured:
        return []
    numbers = [number for number, _ in values]
    first, last = min(numbers), max(numbers)
    low, high = min(v for _, v in measured), max(v for _, v in measured)
    plot_width = width - MARGIN_LEFT - MARGIN_RIGHT
    plot_height = height - MARGIN_TOP - MARGIN_BOTTOM
    points = []
    for number, value in measured:
        x = MARGIN_LEFT + (plot_width * (number - first) / (last - first) if last > first else plot_width / 2)
        y = MARGIN_TOP + (plot_height * (high - value) / (high - low) if high > low else plot_height / 2)
        points.append((number, value, round(x, 2), round(y, 2)))
    return points


def _label(value: float) -> str:
    return f"{value:.4g}"


def chart_svg(name: str, values: list, dates: dict) -> str:
    """The SVG of one learning curve: ``values`` as [(session number, value or None)], ``dates`` number -> text."""
    points = chart_points(values)
    title = html_text.escape(name)
    parts = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{CHART_WIDTH}" height="{CHART_HEIGHT}" '
             f'data-curve="{title}" role="img" aria-label="{title} over sessions" style="background:#fff">',
             f'<text x="{MARGIN_LEFT}" y="12" font-size="11" font-weight="bold">{title}</text>']
    bottom = CHART_HEIGHT - MARGIN_BOTTOM
    parts.append(f'<line x1="{MARGIN_LEFT}" y1="{bottom}" x2="{CHART_WIDTH - MARGIN_RIGHT}" y2="{bottom}" stroke="#999"/>')
    parts.append(f'<line x1="{MARGIN_LEFT}" y1="{MARGIN_TOP}" x2="{MARGIN_LEFT}" y2="{bottom}" stroke="#999"/>')
    if not points:
        parts.append(f'<text x="{MARGIN_LEFT + 8}" y="{MARGIN_TOP + 40}" font-size="11" fill="#666">not measured</text>')
    else:
        values_only = [value for _, value, _, _ in points]
        parts.append(f'<text x="{MARGIN_LEFT - 4}" y="{MARGIN_TOP + 4}" font-size="10" text-anchor="end">'
                     f'{_label(max(values_only))}</text>')
        parts.append(f'<text x="{MARGIN_LEFT - 4}" y="{bottom}" font-size="10" text-anchor="end">'
                     f'{_label(min(values_only))}</text>')
        numbers = [number for number, _ in values]
        parts.append(f'<text x="{MARGIN_LEFT}" y="{CHART_HEIGHT - 6}" font-size="10">session {min(numbers)}</text>')
        parts.append(f'<text x="{CHART_WIDTH - MARGIN_RIGHT}" y="{CHART_HEIGHT - 6}" font-size="10" '
                     f'text-anchor="end">{max(numbers)}</text>')
        polyline = " ".join(f"{x},{y}" for _, _, x, y in points)
        parts.append(f'<polyline points="{polyline}" fill="none" stroke="#1565c0" stroke-width="1.5"/>')
        for number, value, x, y in points:
            tip = html_text.escape(f"session {number}, {dates.get(number, '')}: {_label(value)}")
            parts.append(f'<circle cx="{x}" cy="{y}" r="3.5" fill="#1565c0" data-number="{number}" '
                         f'data-value="{value!r}"><title>{tip}</title></circle>')
    parts.append("</svg>")
    return "".join(parts)


def default_metrics(available: list) -> list:
    preferred = [name for name in KEY_METRICS if name in available]
    return (preferred or list(available))[:DEFAULT_METRIC_COUNT]


class ProgressPanel:
    """The Progress panel's state, its refresh from the records, and its widgets (``build`` inside the drawer)."""

    def __init__(self, server, records_url: str | None = None):
        self.server = server
        self.records_url = records_url
        self._records = None
        server.state.update({"vc_pg_trainees": [], "vc_pg_trainee": None, "vc_pg_metric_items": [],
                             "vc_pg_metrics": [], "vc_pg_charts": [], "vc_pg_error": "", "vc_pg_database": "",
                             "vc_pg_sessions": 0})
        server.state.change("vc_pg_trainee")(self._trainee_changed)
        server.state.change("vc_pg_metrics")(self._metrics_changed)
        server.trigger("vc_pg_refresh")(self.refresh)
        server.trigger("vc_pg_opened")(self.opened)

    def opened(self) -> None:
        """The panel's title was clicked: read the records the first time.

        Not at start: a session that never looks at them neither waits for a
        remote database nor creates the user's file.
        """
        if self._records is None and not self.server.state.vc_pg_error:
            self.refresh()

    def _store(self):
        if self._records is None:
            # A short connection timeout: the page waits for it.
            self._records = database.open(self.records_url, connect_timeout_s=3)
        return self._records

    def refresh(self) -> None:
        """Read the trainees again and redraw the chosen one's curves."""
        state = self.server.state
        try:
            records = self._store()
            state.vc_pg_database = str(records)
            names = [t.name for t in records.trainees()]
            state.vc_pg_error = ""
        except database.RecordsError as error:
            state.vc_pg_error = f"The trainee records cannot be read: {error}"
            state.vc_pg_trainees, state.vc_pg_charts = [], []
            return
        state.vc_pg_trainees = names
        if state.vc_pg_trainee not in names:
            state.vc_pg_trainee = names[0] if len(names) == 1 else None
        self._draw(new_trainee=True)

    def _trainee_changed(self, **_) -> None:
        self._draw(new_trainee=True)

    def _metrics_changed(self, **_) -> None:
        self._draw(new_trainee=False)

    def _draw(self, new_trainee: bool) -> None:
        state = self.server.state
        trainee = state.vc_pg_trainee
        if not trainee or self._records is None:
            state.vc_pg_charts, state.vc_pg_sessions = [], 0
            return
        try:
            if new_trainee:
                available = self._records.metric_names(trainee)
                state.vc_pg_metric_items = available
                if not set(state.vc_pg_metrics or []) <= set(available) or not state.vc_pg_metrics:
                    state.vc_pg_metrics = default_metrics(available)
            names = ["score", *[n for n in state.vc_pg_metrics or [] if n != "score"]]
            curve = self._records.learning_curve(trainee, names)
        except database.RecordsError as error:
            state.vc_pg_error = f"The trainee records cannot be read: {error}"
            return
        dates = {p.number: p.started.strftime("%Y-%m-%d") for p in curve}
        state.vc_pg_sessions = len(curve)
        state.vc_pg_charts = [{"name": name, "svg": chart_svg(name, [(p.number, p.values[name]) for p in curve], dates)}
                              for name in names]

    def build(self) -> None:
        with v3.VExpansionPanel(value="progress"):
            v3.VExpansionPanelTitle("Progress", click="trigger('vc_pg_opened')", raw_attrs=['data-testid="progress-panel"'])
            self._content()

    def _content(self) -> None:
        with v3.VExpansionPanelText():
            with html.Div(classes="d-flex align-center ga-1"):
                v3.VSelect(v_model=("vc_pg_trainee",), items=("vc_pg_trainees",), label="Trainee", density="compact",
                           hide_details=True, raw_attrs=['data-testid="progress-trainee"'])
                v3.VBtn(icon="mdi-refresh", size="small", variant="text", click="trigger('vc_pg_refresh')",
                        raw_attrs=['data-testid="progress-refresh"'])
            v3.VSelect(v_model=("vc_pg_metrics",), items=("vc_pg_metric_items",), label="Metrics beside the score",
                       multiple=True, chips=True, density="compact", hide_details=True, classes="mt-2",
                       v_if="vc_pg_trainee", raw_attrs=['data-testid="progress-metrics"'])
            html.Div("{{ vc_pg_sessions }} sessions, oldest on the left", v_if="vc_pg_trainee",
                     classes="text-caption mt-1", raw_attrs=['data-testid="progress-sessions"'])
            with html.Div(v_for="c in vc_pg_charts", key="c.name", classes="mt-1"):
                html.Div(v_html="c.svg", raw_attrs=[':data-chart="c.name"'])
            html.Div("Records: {{ vc_pg_database }}", v_if="vc_pg_database", classes="text-caption mt-1")
            v3.VAlert(v_if="vc_pg_error", text=("vc_pg_error",), type="warning", density="compact", classes="mt-2",
                      raw_attrs=['data-testid="progress-error"'])
