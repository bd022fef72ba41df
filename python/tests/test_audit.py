"""The self-collision audit: the same pairs, verdicts and SRDF as `clearway audit`, and its bounds."""
import math

import pytest

import clearway
from conftest import REPO, shared

ARM6 = REPO / "robots" / "arm6"


def binomial_cdf(k, n, p):
    return sum(math.comb(n, i) * p**i * (1 - p) ** (n - i) for i in range(k + 1))


@pytest.fixture(scope="module")
def arm6_audit():
    return clearway.audit(str(ARM6 / "arm6.urdf"), srdf=str(ARM6 / "arm6.srdf"), samples=2000, seed=3)


def test_audit_equals_the_tool(arm6_audit, tool, tmp_path):
    out = tmp_path / "arm6.srdf"
    lines = tool("audit", ARM6 / "arm6.urdf", "--srdf", ARM6 / "arm6.srdf", "--samples", 2000, "--seed", 3,
                 "--srdf-out", out)
    assert arm6_audit.to_srdf() == out.read_text()
    counts = arm6_audit.counts()
    near = sum(p.near_miss for p in arm6_audit.pairs)
    summary = (f"arm6: {len(arm6_audit.pairs)} pairs: {counts['Adjacent']} Adjacent {counts['Default']} Default "
               f"{counts['Always']} Always {counts['Never']} Never {counts['checked']} checked "
               f"({near} Never pairs came within 1 mm)")
    assert summary in lines
    # The pairs where the given SRDF and the audit disagree, as the tool lists them.
    differ = [f"differs: {p.link_a} {p.link_b}: SRDF {p.srdf_reason or 'checked'}, audit {p.reason or 'checked'}"
              for p in arm6_audit.pairs if p.srdf_reason != p.reason]
    assert differ == [line.split(" (")[0] for line in lines if line.startswith("differs: ")]
    assert f"{len(differ)} pairs differ from {ARM6 / 'arm6.srdf'}" in lines


def test_verdicts_carry_their_evidence(arm6_audit):
    pairs = arm6_audit.pairs
    assert arm6_audit.robot_name == "arm6" and arm6_audit.samples == 2000 and arm6_audit.seed == 3
    assert {p.reason for p in pairs} >= {"Adjacent", "Never"}
    assert any(p.srdf_reason for p in pairs)
    for p in pairs:
        if p.reason == "Adjacent":
            assert p.samples == 0 and math.isnan(p.min_clearance)
            continue
        assert 0 <= p.colliding <= p.samples
        if p.reason == "Never":
            assert p.colliding == 0 and p.min_clearance > 0
        if p.colliding == 0 and p.samples == 2000:
            # With no collision in n samples the 95% bound solves (1 - p)^n = 0.05.
            assert p.p_upper == pytest.approx(1 - 0.05 ** (1 / p.samples), rel=1e-9)


def test_clopper_pearson_upper_bound():
    for k, n in [(0, 10), (3, 20), (17, 50), (99, 100)]:
        p = clearway.clopper_pearson_upper(k, n)
        assert k / n < p < 1 and binomial_cdf(k, n, p) == pytest.approx(0.05, abs=1e-9)
    assert clearway.clopper_pearson_upper(5, 5) == 1 and clearway.clopper_pearson_upper(0, 0) == 1


def test_the_same_seed_gives_the_same_audit_whatever_the_threads():
    urdf = str(shared("robots/panda/panda.urdf"))
    one = clearway.audit(urdf, samples=300, seed=5, threads=1)
    two = clearway.audit(urdf, samples=300, seed=5, threads=2)
    assert one.to_srdf() == two.to_srdf()
    assert [(p.link_a, p.link_b, p.colliding) for p in one.pairs] == [(p.link_a, p.link_b, p.colliding) for p in two.pairs]
    assert any(p.colliding for p in one.pairs)


def test_bad_audits_raise(tmp_path):
    with pytest.raises(ValueError, match="samples"):
        clearway.audit(str(ARM6 / "arm6.urdf"), samples=0)
    with pytest.raises(clearway.LoadError) as e:
        clearway.audit(str(ARM6 / "arm6.urdf"), srdf=str(tmp_path / "none.srdf"))
    assert e.value.file == str(tmp_path / "none.srdf")


def test_too_many_threads_are_capped_with_a_warning():
    # 100,000 threads were all asked of the system, which aborted the process when it could not give them.
    urdf = str(ARM6 / "arm6.urdf")
    with pytest.warns(RuntimeWarning, match="threads=100000 is more than this machine runs at once"):
        capped = clearway.audit(urdf, samples=50, seed=3, threads=100000)
    one = clearway.audit(urdf, samples=50, seed=3, threads=1)
    assert [(p.reason, p.colliding) for p in capped.pairs] == [(p.reason, p.colliding) for p in one.pairs]
