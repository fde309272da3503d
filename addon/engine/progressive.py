"""The progressive render loop's decisions, free of Blender and of the module so
they can be reasoned about on their own: how many passes the next ``run()`` takes,
when the film goes to the screen, and what the stats line says."""

import math

# One run() call should take about this long, so cancel and display stay responsive.
BATCH_SECONDS = 0.25


class PassSchedule:
    """Batches of passes within a pass budget and an optional time limit."""

    def __init__(self, passes, time_limit=0.0, batch_seconds=BATCH_SECONDS):
        self.passes = passes
        self.time_limit = time_limit
        self.batch_seconds = batch_seconds
        self.done = 0
        self.seconds_per_pass = None
        # After the first (compiling) batch: passes and their wall time, for projections.
        self.steady_passes = 0
        self.steady_seconds = 0.0

    def next_batch(self, elapsed):
        """Passes for the next run() call; 0 when the render is finished."""
        left = self.passes - self.done
        if left <= 0 or (self.time_limit > 0.0 and elapsed >= self.time_limit):
            return 0
        if self.seconds_per_pass is None:
            return 1  # the first pass also compiles programs: measure before batching
        budget = self.batch_seconds
        if self.time_limit > 0.0:
            budget = min(budget, self.time_limit - elapsed)
        batch = int(budget / max(self.seconds_per_pass, 1e-6))
        return max(1, min(left, batch))

    def record(self, batch, seconds):
        """Notes a finished batch; the pass time is a running average that forgets
        the first (compiling) pass quickly."""
        self.done += batch
        per_pass = seconds / batch
        if self.seconds_per_pass is None:
            self.seconds_per_pass = per_pass
        else:
            self.steady_passes += batch
            self.steady_seconds += seconds
            self.seconds_per_pass = 0.5 * (self.seconds_per_pass + per_pass)

    def progress(self, elapsed):
        fraction = self.done / self.passes
        if self.time_limit > 0.0:
            fraction = max(fraction, elapsed / self.time_limit)
        return min(1.0, fraction)

    def remaining_seconds(self, elapsed):
        if self.seconds_per_pass is None:
            return math.inf
        remaining = (self.passes - self.done) * self.seconds_per_pass
        if self.time_limit > 0.0:
            remaining = min(remaining, self.time_limit - elapsed)
        return max(0.0, remaining)


# A render projected to take longer than this, with no time limit, is announced as soon
# as its pass time is known: the Final preset at 1080p is about 8 hours on llvmpipe.
LONG_RENDER_SECONDS = 600.0


def long_render_warning(schedule, elapsed, device):
    """The warning for a render that will run long, or None: once the pass time is known
    (two passes after the compiling one, whose time it leaves out), when no time limit caps
    it. The projection is the wall time a pass has taken, the add-on's own work included."""
    if schedule.time_limit > 0.0 or schedule.steady_passes < 2:
        return None
    per_pass = schedule.steady_seconds / schedule.steady_passes
    total = elapsed + (schedule.passes - schedule.done) * per_pass
    if total < LONG_RENDER_SECONDS:
        return None
    return (f"this render will take about {format_duration(total)} ({schedule.passes:,} "
            f"passes at {per_pass:.3g} s each on {device}); press Esc and "
            "set Sampling > Time Limit, fewer passes or the Preview preset to finish sooner")


def projected_seconds(passes, time_limit, pass_seconds):
    """A render's length before it starts: its passes at the estimated pass time, capped
    by the time limit."""
    total = passes * pass_seconds
    return min(total, time_limit) if time_limit > 0.0 else total


class DisplayClock:
    """When to stream the film into Blender: often while the image changes most
    (the first seconds), about once per second after that."""

    STEPS = ((2.0, 0.25), (10.0, 0.5), (math.inf, 1.0))  # (until elapsed, interval)

    def __init__(self):
        self.last = -math.inf

    def due(self, elapsed):
        interval = next(step for until, step in self.STEPS if elapsed < until)
        if elapsed - self.last >= interval:
            self.last = elapsed
            return True
        return False


def format_duration(seconds):
    if not math.isfinite(seconds):
        return "--:--"
    seconds = int(round(seconds))
    hours, rest = divmod(seconds, 3600)
    minutes, seconds = divmod(rest, 60)
    return f"{hours}:{minutes:02d}:{seconds:02d}" if hours else f"{minutes:02d}:{seconds:02d}"


def format_rate(value):
    for scale, suffix in ((1e9, "G"), (1e6, "M"), (1e3, "k")):
        if value >= scale:
            return f"{value / scale:.2f} {suffix}"
    return f"{value:.0f} "


def stats_line(schedule, stats, elapsed):
    """Pass 12/64 | 1.23 M photons/s | radius 0.0123 | 00:05 elapsed, 00:20 left"""
    parts = [f"Pass {schedule.done}/{schedule.passes}"]
    if stats.get("estimator") == "vcm":
        # VCM: its light paths where it traces any (docs/vcm.md).
        variant = stats.get("variant", "").split(",")
        if stats.get("photons_per_second") and any(v in variant for v in
                                                   ("vcm=lt", "vcm=pt+lt", "vcm=pt+lt+vm")):
            parts.append(f"{format_rate(stats['photons_per_second'])}light paths/s")
    else:
        if stats.get("photons_per_second"):
            parts.append(f"{format_rate(stats['photons_per_second'])}photons/s")
        if stats.get("mean_radius"):
            parts.append(f"radius {stats['mean_radius']:.4g}")
    devices = stats.get("devices", [])
    if len(devices) > 1:
        rates = ", ".join(f"{d['passes_per_second']:.3g}" for d in devices)
        parts.append(f"{len(devices)} devices: {rates} passes/s")
    parts.append(f"{format_duration(elapsed)} elapsed, "
                 f"{format_duration(schedule.remaining_seconds(elapsed))} left")
    return " | ".join(parts)
