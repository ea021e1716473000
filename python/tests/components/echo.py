"""A test component: publishes gain × the first `publishes.len` values of its first input, and
misbehaves on request (params: raise_at, bad_len_at, diverge_at, print)."""

from uio_component import Diverged, run


def setup(config):
    print("setting up")  # must not come before `ready` on the launcher's pipe
    if config.params.get("fail_setup"):
        raise RuntimeError("no such gain")
    return dict(config.params, n=config.publishes.len)


def step(k, inputs, p):
    if p.get("print"):
        print(f"step {k}")  # must not reach the launcher's stdout pipe
    if k == p.get("raise_at"):
        return 1 / 0
    if k == p.get("bad_len_at"):
        return [1.0] * (p["n"] + 1)
    if k == p.get("diverge_at"):
        raise Diverged("x1 = inf")
    return p.get("gain", 1.0) * inputs[0][: p["n"]]


if __name__ == "__main__":
    run(step, setup)
