"""The token bucket that paces fragmented messages (with a fake clock: no timing asserts)."""

from __future__ import annotations

import pytest

from rosl.bus import pacing
from rosl.bus.multicast import MulticastTransport
from rosl.bus.pacing import DEFAULT_BURST, DEFAULT_RATE, Pacer, pacer_from_env


class FakeClock:
    def __init__(self) -> None:
        self.now = 100.0
        self.slept: list[float] = []

    def perf_counter(self) -> float:
        return self.now

    def sleep(self, seconds: float) -> None:
        self.slept.append(seconds)
        self.now += seconds


@pytest.fixture
def clock(monkeypatch: pytest.MonkeyPatch) -> FakeClock:
    fake = FakeClock()
    monkeypatch.setattr(pacing.time, "perf_counter", fake.perf_counter)
    monkeypatch.setattr(pacing.time, "sleep", fake.sleep)
    return fake


def test_a_burst_passes_without_sleeping(clock: FakeClock) -> None:
    p = Pacer(rate=1000.0, burst=10_000)
    for _ in range(10):
        p.spend(1000)
    assert clock.slept == []


def test_beyond_the_burst_it_sleeps_for_the_debt(clock: FakeClock) -> None:
    p = Pacer(rate=1000.0, burst=10_000)
    p.spend(10_000)
    p.spend(500)
    assert clock.slept == [pytest.approx(0.5)]
    # the sleep paid the debt: the next spend of the same size sleeps the same again
    p.spend(500)
    assert clock.slept[-1] == pytest.approx(0.5)


def test_overall_rate_is_held(clock: FakeClock) -> None:
    rate = 1e6
    p = Pacer(rate=rate, burst=100_000)
    start = clock.now
    total = 0
    for _ in range(1000):
        p.spend(64_952)
        total += 64_952
    elapsed = clock.now - start
    # fake time: what the bucket allowed, minus the initial burst, at the configured rate
    assert elapsed == pytest.approx((total - 100_000) / rate, rel=0.01)


def test_tiny_debts_carry_over_instead_of_sleeping(clock: FakeClock) -> None:
    p = Pacer(rate=1e9, burst=0)
    p.spend(100)  # a debt of 100 ns: too small to sleep for
    assert clock.slept == []
    for _ in range(10_000):
        p.spend(100)
    assert clock.slept, "debts that add up must eventually be slept"


def test_idle_time_refills_only_up_to_the_burst(clock: FakeClock) -> None:
    p = Pacer(rate=1000.0, burst=1000)
    p.spend(1000)
    clock.now += 3600  # an hour idle
    p.spend(1000)
    assert clock.slept == []
    p.spend(1000)
    assert clock.slept == [pytest.approx(1.0)]


@pytest.mark.parametrize(
    ("value", "loopback", "rate"),
    [
        (None, True, DEFAULT_RATE[True]),
        (None, False, DEFAULT_RATE[False]),
        ("", True, DEFAULT_RATE[True]),
        ("2e8", True, 2e8),
        (" 5000000 ", False, 5e6),
        ("abc", True, DEFAULT_RATE[True]),
        ("1", True, 1e5),  # floored: a typo must not stall big messages forever
        ("-5", False, 1e5),
    ],
)
def test_rate_from_environment(
    monkeypatch: pytest.MonkeyPatch, value: str | None, loopback: bool, rate: float
) -> None:
    if value is None:
        monkeypatch.delenv("ROSL_MAX_RATE", raising=False)
    else:
        monkeypatch.setenv("ROSL_MAX_RATE", value)
    p = pacer_from_env(loopback)
    assert p.rate == rate
    assert p.burst == DEFAULT_BURST


def test_burst_is_well_under_a_receive_buffer() -> None:
    from rosl.bus.multicast import RCVBUF_WARN_BELOW

    assert DEFAULT_BURST <= RCVBUF_WARN_BELOW


def test_transport_uses_the_loopback_rate(domain_id: int, monkeypatch: pytest.MonkeyPatch) -> None:
    from rosl.bus.multicast import Addressing

    monkeypatch.delenv("ROSL_MAX_RATE", raising=False)
    t = MulticastTransport(Addressing(domain_id))
    try:
        assert t.pacer.rate == DEFAULT_RATE[True]
        assert t.max_datagram == 65000
    finally:
        t.close()
