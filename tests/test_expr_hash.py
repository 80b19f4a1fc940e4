"""Expression nodes compute their hash once; equal nodes hash equally, and a node sent to
another process (pickled, as cluster pieces and bench runs are) is found by equality
there: the cached hash, which depends on the process's string hashing, is not sent."""
import pickle
import subprocess
import sys

from fossil_dsl.ir import expr as E


def _network_like():
    x0, x1 = E.Var("x0"), E.Var("x1")
    hidden = [E.apply("tanh", E.add(E.mul(E.Num(k), x0), x1)) for k in range(1, 4)]
    return E.add(*(E.mul(h, g) for h in hidden for g in hidden))


def test_equal_nodes_hash_equally_and_the_hash_is_kept():
    a, b = _network_like(), _network_like()
    assert a is not b and a == b and hash(a) == hash(b)
    assert a.__dict__["_hash"] == hash(a)
    assert {a: 1}[b] == 1


def test_a_pickled_node_carries_no_hash_and_is_found_in_another_process():
    data = pickle.dumps(_network_like())
    assert b"_hash" not in data
    script = ("import pickle, sys\n"
              "from tests.test_expr_hash import _network_like\n"
              "node = pickle.loads(sys.stdin.buffer.read())\n"
              "print({_network_like(): 'found'}.get(node, 'missing'))\n")
    for seed in ("1", "2"):
        out = subprocess.run([sys.executable, "-c", script], input=data, capture_output=True,
                             env={"PYTHONHASHSEED": seed, "PATH": ""}, cwd=_root(),
                             check=True)
        assert out.stdout.decode().strip() == "found"


def _root():
    from pathlib import Path
    return Path(__file__).resolve().parent.parent
