"""Side-by-side measurements against the tools a user would pick instead (issue 8).

So far: (c) event throughput — the same two models as `cargo bench -p vworks-se --bench
events`, in SimPy: a signal ping-pong between two processes, and a ring of N processes each
waiting until a shared counter reaches its turn. Prints rounds per second and SimPy's
processed events per second; compare with the vworks bench's output.

    .venv/bin/python bench/compare.py
"""

import time

import simpy


class Counted(simpy.Environment):
    """A SimPy environment that counts the events it processes."""

    def __init__(self):
        super().__init__()
        self.processed = 0

    def step(self):
        self.processed += 1
        super().step()


def ping_pong(rounds):
    env = Counted()
    ping, pong = [env.event()], [env.event()]

    def a():
        for _ in range(rounds):
            ping[0].succeed()
            yield pong[0]
            pong[0] = env.event()

    def b():
        for _ in range(rounds):
            yield ping[0]
            ping[0] = env.event()
            pong[0].succeed()

    env.process(a())
    env.process(b())
    env.run()
    return env.processed


def ring(n, rounds):
    """N processes; each waits until `turn` is its own, then advances it (a condition
    re-tested on every change, as wait_until is)."""
    env = Counted()
    state = {"turn": 0, "changed": env.event()}

    def robot(k):
        for i in range(rounds):
            while state["turn"] != i * n + k:
                yield state["changed"]
            state["turn"] += 1
            changed, state["changed"] = state["changed"], env.event()
            changed.succeed()

    for k in range(n):
        env.process(robot(k))
    env.run()
    return env.processed


def measure(name, f, rounds, *args):
    best = float("inf")
    processed = 0
    for _ in range(3):
        t0 = time.perf_counter()
        processed = f(*args)
        best = min(best, time.perf_counter() - t0)
    print(
        f"(c) SimPy {name}: {rounds} rounds in {best * 1e3:.1f} ms = {rounds / best:,.0f} rounds/s; "
        f"{processed} events = {processed / best / 1e6:.2f} M events/s"
    )


if __name__ == "__main__":
    rounds = 20_000
    measure("ping-pong", ping_pong, rounds, rounds)
    for n in (2, 8, 32):
        measure(f"set/wait_until ring of {n}", ring, rounds, n, rounds // n)
