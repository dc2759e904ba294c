"""What kind of cause would fit a residual that no named piece explains.

Read from the sign pattern of the residual (measured − model) on the temperature and the
displacement channels, and from its shape in time; never a name from the catalogue:

* displacements off, temperatures agreeing: the mechanical path between the displacement
  sensor's faces differs (a stiffness, an expansion, a dimension), not the heat flow;
* temperatures off with one sign: more (measured warmer) or less heat in the frame than the
  model has; with both signs: heat distributed differently inside it;
* temperatures off, displacements agreeing: something local to the thermocouples;
* a displacement residual that follows the model's own thermal deformation (correlation
  ≥ :data:`FOLLOWS`) is a change of its scale; one that grows with time, a slow drift; one
  that changes sign on its own, a cause acting at other times than the model's inputs.
"""
from __future__ import annotations

import numpy as np

from gatetherm.studies.diagnosis.locate import Finding, significant, smooth
from gatetherm.studies.diagnosis.replay import label, resolution

FOLLOWS = 0.9
"""Correlation with the model's own response (or with time) above which a residual 'follows' it."""


def _corr(a: np.ndarray, b: np.ndarray) -> float:
    m = np.isfinite(a) & np.isfinite(b)
    if m.sum() < 3 or np.std(a[m]) == 0 or np.std(b[m]) == 0:
        return 0.0
    return float(np.corrcoef(a[m], b[m])[0, 1])


def unexplained(findings) -> dict[str, list[str]]:
    """{channel: [phases where its residual is significant]}."""
    out: dict[str, list[str]] = {}
    for f in findings:
        if f.significant:
            out.setdefault(f.channel, []).append(f"{f.phase.label} {f.phase.span()}")
    return out


def kind_of_cause(t: np.ndarray, res: dict, model: dict, findings: list[Finding]) -> str:
    """One paragraph: what kind of cause would fit the significant residual ``res`` ({channel: measured −
    model}) of a run whose model columns are ``model``."""
    sig = unexplained(findings)
    if not sig:
        return ""
    temps = [c for c in res if c.endswith("_degC") and c in sig]
    disp = [c for c in res if c.endswith("_um") and c in sig]
    out = []
    if disp and not temps:
        out.append("The temperatures agree and the deformation does not: a difference in the mechanical path "
                   "between the displacement sensor's faces (a stiffness, an expansion coefficient or a dimension "
                   "of the parts in that path), not in the heat flow.")
    if temps:
        sign = {}
        for c in temps:
            s = smooth(t, res[c])
            m = significant(t, res[c], resolution(c))
            sign[c] = float(np.sign(np.nanmean(s[m]))) if m.any() else 0.0
        warm = [label(c) for c in temps if sign[c] > 0]
        cool = [label(c) for c in temps if sign[c] < 0]
        if warm and not cool:
            out.append(f"Measured warmer than the model at {', '.join(warm)}: more heat enters the frame, or less "
                       "leaves it, than the model has (a source, a film, a supply, a contact, a heat path).")
        elif cool and not warm:
            out.append(f"Measured cooler than the model at {', '.join(cool)}: less heat enters the frame, or more "
                       "leaves it, than the model has (a source, a film, a supply, a contact, a heat path).")
        else:
            out.append(f"Measured warmer at {', '.join(warm)} and cooler at {', '.join(cool)}: heat is distributed "
                       "differently inside the frame (where it enters or leaves, or a conduction path).")
        if not disp and any(c.endswith("_um") for c in res):
            out.append("The displacements agree: the cause is local to those thermocouples (their position or "
                       "contact) or a heat path that does not bend the frame.")
    for c in disp:
        own = model[c] - model[c][0]
        r = _corr(res[c], own)
        if abs(r) >= FOLLOWS:
            k = float(np.nansum(res[c] * own) / max(np.nansum(own * own), 1e-30))
            out.append(f"The residual of {label(c)} follows the model's own {label(c)} (correlation {r:+.2f}, "
                       f"{100 * k:+.0f} % of it): its thermal deformation is scaled, as by a dimension or an "
                       "expansion coefficient.")
        elif abs(_corr(res[c], t)) >= FOLLOWS:
            out.append(f"The residual of {label(c)} grows steadily with time: a slow drift of the frame or of "
                       "the sensor's mounting.")
        else:
            s = smooth(t, res[c])
            flips = int(np.sum(np.diff(np.sign(s[np.isfinite(s) & (np.abs(s) > resolution(c))])) != 0))
            out.append(f"The residual of {label(c)} has a shape of its own (correlation with the model's {label(c)} "
                       f"{r:+.2f}, {flips} changes of sign): a cause acting at other times than the model's "
                       "inputs, such as an input the file does not record.")
    return " ".join(out)
