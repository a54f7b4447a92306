"""Vehicle body, wheel-ground contact and kinematics (differential drive and Ackermann bicycle).

Each step (fixed dt):

1. Every drive unit's motor updates its current and gives a torque at the wheel.
2. Each wheel spins up by that torque minus viscous friction.
3. Two kinds of bounded impulse act on the coupled system of wheels and body: at each tyre a
   contact impulse P_i (force * dt, forward positive) that makes the tyre roll without slip,
   r * w_i' = v' - y_i * wz' (y_i: the tyre's lateral offset, left positive), bounded by
   mu * N_i * dt; and at each wheel a dry-friction impulse Q_i (gearbox Coulomb friction plus the
   tyre's rolling resistance c_rr * N_i * r, times dt) that stops the wheel, w_i' = 0, if it can.
   All are solved together as one small linear system; one that would exceed its bound is fixed
   at the bound (a slipping tyre; a wheel that keeps turning against friction) and the others
   are solved again. So a robot at rest stays at rest until the drive torque beats the dry
   friction (the plant's mechanical deadband), and comes to rest exactly, not asymptotically.
4. The body moves along the exact arc for its new (v, wz); wheel angles advance by w * dt.

Differential drive: two driven wheels at y = +track/2 (left, wheel 0) and -track/2 (right, wheel 1),
free casters elsewhere; wz is a degree of freedom. Ackermann: one drive unit for the rear axle
(the motor turns both rear wheels through the differential; its encoder measures the axle), a
bicycle model with wz = v * tan(delta) / wheelbase and no lateral slip, so the body's effective mass
for the drive is m + Iz * (tan(delta) / L)^2. The pose is the midpoint of the driven axle.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from emulator.plant.encoder import QuadratureEncoder
from emulator.plant.motor import DcMotor

GRAVITY = 9.81


@dataclass(frozen=True, slots=True)
class BodyParams:
    mass_kg: float
    yaw_inertia_kg_m2: float
    wheel_inertia_kg_m2: float
    """Inertia of one driven wheel (or of the driven axle) itself, without the motor."""
    drive_load_fraction: float
    """Share of the weight on the driven wheels (the rest is on casters or the steered axle)."""
    rolling_resistance: float
    """Rolling resistance coefficient c_rr of the driven tyres."""
    mu: float = 0.8
    """Tyre-ground friction coefficient; math.inf for a tyre that never slips."""


class DriveUnit:
    """A motor, its wheel (or axle) and the encoder on it."""

    __slots__ = (
        "angle_rad",
        "encoder",
        "inertia",
        "motor",
        "normal_n",
        "omega_rad_s",
        "slipping",
        "stalled",
        "torque_nm",
        "y_m",
    )

    def __init__(self, motor: DcMotor, encoder: QuadratureEncoder | None, y_m: float, inertia: float) -> None:
        self.motor = motor
        self.encoder = encoder
        self.y_m = y_m
        self.inertia = inertia
        self.normal_n = 0.0
        self.omega_rad_s = 0.0
        self.angle_rad = 0.0
        self.torque_nm = 0.0
        self.stalled = False
        self.slipping = False


class Vehicle:
    """Body state and the step described in the module docstring."""

    def __init__(
        self,
        body: BodyParams,
        units: list[DriveUnit],
        wheel_radius_m: float,
        kinematics: str,
        wheelbase_m: float,
    ) -> None:
        self.body = body
        self.units = units
        self.radius = wheel_radius_m
        self.ackermann = kinematics == "ackermann"
        self.wheelbase = wheelbase_m
        self.x_m = 0.0
        self.y_m = 0.0
        self.theta_rad = 0.0
        self.v_m_s = 0.0
        self.wz_rad_s = 0.0
        self.distance_m = 0.0
        """Path length travelled by the pose point (always increasing)."""
        self.mu = body.mu
        self.lifted = False
        """On a stand: no tyre touches the ground, the body stays where it is, the wheels spin free."""
        self._static = False
        self._load_n = body.mass_kg * GRAVITY * body.drive_load_fraction / len(units)
        for unit in units:
            unit.normal_n = self._load_n

    def set_lifted(self, lifted: bool) -> None:
        """Put the robot on a stand (or back down): the body stops, the tyres carry no load."""
        self.lifted = lifted
        self.v_m_s = self.wz_rad_s = 0.0
        for unit in self.units:
            unit.normal_n = 0.0 if lifted else self._load_n
            unit.slipping = False

    def step(self, dt: float, steer_rad: float) -> None:
        body = self.body
        r = self.radius
        units = self.units
        n = len(units)
        w_free = [0.0] * n
        j_inv = [0.0] * n
        for i, u in enumerate(units):
            tau = u.motor.step(u.omega_rad_s)
            u.torque_nm = tau
            if u.stalled:
                u.omega_rad_s = 0.0
                continue
            inv = 1.0 / u.inertia
            w_free[i] = u.omega_rad_s + dt * inv * (tau - u.motor.params.viscous_nm_s_rad * u.omega_rad_s)
            j_inv[i] = inv
        if self.ackermann:
            k = math.tan(steer_rad) / self.wheelbase
            m_inv = 1.0 / (body.mass_kg + body.yaw_inertia_kg_m2 * k * k)
            iz_inv = 0.0
            wz = 0.0
        else:
            k = 0.0
            m_inv = 1.0 / body.mass_kg
            iz_inv = 1.0 / body.yaw_inertia_kg_m2
            wz = self.wz_rad_s
        v = self.v_m_s
        if self.lifted:
            contact, dry = [0.0] * n, self._free_spin(w_free, j_inv, dt)
            self._static = False
        else:
            contact, dry = self._impulses(w_free, j_inv, v=v, wz=wz, m_inv=m_inv, iz_inv=iz_inv, dt=dt)
        total = 0.0
        yaw = 0.0
        for i, u in enumerate(units):
            total += contact[i]
            yaw -= u.y_m * contact[i]
            if not u.stalled:
                u.omega_rad_s = w_free[i] - j_inv[i] * (r * contact[i] + dry[i])
        v += total * m_inv
        wz = v * k if self.ackermann else wz + yaw * iz_inv
        if self._static:
            # Every wheel held by friction and every tyre gripping: at rest, exactly.
            v = wz = 0.0
            for u in units:
                u.omega_rad_s = 0.0
        self.v_m_s = v
        self.wz_rad_s = wz
        self._move(v * dt, wz * dt)
        for u in units:
            u.angle_rad += u.omega_rad_s * dt
            if u.encoder is not None:
                u.encoder.update(u.angle_rad)

    def _impulses(
        self, w: list[float], j_inv: list[float], *, v: float, wz: float, m_inv: float, iz_inv: float, dt: float
    ) -> tuple[list[float], list[float]]:
        """Contact impulses P_i and dry-friction impulses Q_i (torque * dt at the wheel) of one step.

        Each is first asked to hold its constraint exactly (tyre rolls without slip; wheel stops
        turning); one that would need more than its bound (mu * N * dt; dry torque * dt) is fixed
        at the bound, with that sign, and the rest are solved again. Velocity changes are linear
        in the impulses:
            w_i' = w_i - J_i^-1 (r P_i + Q_i),  v' = v + sum(P) / m,  wz' = wz - sum(y_j P_j) / Iz.
        """
        units = self.units
        r = self.radius
        n = len(units)
        ys = [u.y_m for u in units]
        # Variables 0..n-1: P_i; n..2n-1: Q_i (absent for a stalled wheel, which cannot turn).
        bounds = [self.mu * u.normal_n * dt for u in units]
        bounds += [(u.motor.params.coulomb_nm + self.body.rolling_resistance * u.normal_n * r) * dt for u in units]
        rows: list[list[float]] = []
        rhs: list[float] = []
        for i in range(n):  # tyre i: r w_i' - (v' - y_i wz') = 0
            row = [(r * r * j_inv[i] if j == i else 0.0) + m_inv + ys[i] * ys[j] * iz_inv for j in range(n)]
            row += [r * j_inv[i] if j == i else 0.0 for j in range(n)]
            rows.append(row)
            rhs.append(r * w[i] - (v - ys[i] * wz))
        for i in range(n):  # wheel i: w_i' = 0
            rows.append(
                [r * j_inv[i] if j == i else 0.0 for j in range(n)] + [j_inv[i] if j == i else 0.0 for j in range(n)]
            )
            rhs.append(w[i])
        fast = self._moving_and_gripping(rows, rhs, bounds, w)
        if fast is not None:
            return fast
        live = [i for i in range(2 * n) if not (i >= n and units[i - n].stalled)]
        fixed: dict[int, float] = {}
        values = [0.0] * (2 * n)
        for _ in range(len(live)):
            free = [i for i in live if i not in fixed]
            b = [rhs[i] - sum(rows[i][j] * x for j, x in fixed.items()) for i in free]
            solution = _solve([[rows[i][j] for j in free] for i in free], b)
            worst, worst_ratio = -1, 1.0
            for i, x in zip(free, solution, strict=True):
                values[i] = x
                ratio = abs(x) / bounds[i] if bounds[i] > 0 else (math.inf if x else 0.0)
                if ratio > worst_ratio:
                    worst, worst_ratio = i, ratio
            if worst < 0:
                break
            # Only the worst offender goes to its bound: fixing every violator of the all-stuck
            # solution at once would, e.g., make tyres slip just because a moving robot rolls on.
            fixed[worst] = values[worst] = math.copysign(bounds[worst], values[worst])
        for i, u in enumerate(units):
            u.slipping = i in fixed
        self._static = not fixed
        return values[:n], values[n:]

    def _free_spin(self, w: list[float], j_inv: list[float], dt: float) -> list[float]:
        """Dry-friction impulses of wheels in the air: each stops its wheel if it can, else acts
        at its bound against the motion (no contact, so the wheels do not couple)."""
        dry = []
        for i, u in enumerate(self.units):
            bound = u.motor.params.coulomb_nm * dt
            if u.stalled or j_inv[i] == 0.0:
                dry.append(0.0)
            elif abs(w[i]) <= j_inv[i] * bound:
                dry.append(w[i] / j_inv[i])  # held: the wheel stops exactly
            else:
                dry.append(math.copysign(bound, w[i]))
        return dry

    def _moving_and_gripping(
        self, rows: list[list[float]], rhs: list[float], bounds: list[float], w: list[float]
    ) -> tuple[list[float], list[float]] | None:
        """The usual case, solved directly: every free wheel turning (dry friction at its bound,
        against the motion) and every tyre gripping. None when that guess does not hold."""
        units = self.units
        n = len(units)
        dry = [0.0] * n
        for i, u in enumerate(units):
            if not u.stalled:
                if w[i] == 0.0 or u.omega_rad_s == 0.0:
                    return None
                dry[i] = math.copysign(bounds[n + i], u.omega_rad_s)
        b = [rhs[i] - sum(rows[i][n + j] * dry[j] for j in range(n)) for i in range(n)]
        contact = _solve([row[:n] for row in rows[:n]], b)
        for i, u in enumerate(units):
            if abs(contact[i]) > bounds[i]:
                return None
            if not u.stalled:
                after = w[i] - (rows[n + i][i] * contact[i] + rows[n + i][n + i] * dry[i])
                if after == 0.0 or (after > 0) != (u.omega_rad_s > 0):
                    return None  # friction would stop (or reverse) it within the step
        for u in units:
            u.slipping = False
        self._static = False
        return contact, dry

    def _move(self, ds: float, dth: float) -> None:
        """Exact arc: the chord is ds * sinc(dth/2) long and points along the mid-arc heading."""
        half = dth / 2
        chord = ds * (math.sin(half) / half if abs(half) > 1e-9 else 1.0)
        mid = self.theta_rad + half
        self.x_m += chord * math.cos(mid)
        self.y_m += chord * math.sin(mid)
        self.theta_rad += dth
        self.distance_m += abs(ds)


def _solve(a: list[list[float]], b: list[float]) -> list[float]:
    """Solution of a small dense linear system (Gaussian elimination with partial pivoting)."""
    n = len(b)
    m = [[*row, b[i]] for i, row in enumerate(a)]
    for col in range(n):
        pivot = max(range(col, n), key=lambda i: abs(m[i][col]))
        m[col], m[pivot] = m[pivot], m[col]
        p = m[col][col]
        for i in range(col + 1, n):
            f = m[i][col] / p
            if f:
                mi, mc = m[i], m[col]
                for j in range(col, n + 1):
                    mi[j] -= f * mc[j]
    x = [0.0] * n
    for i in range(n - 1, -1, -1):
        acc = m[i][n] - sum(m[i][j] * x[j] for j in range(i + 1, n))
        x[i] = acc / m[i][i]
    return x
