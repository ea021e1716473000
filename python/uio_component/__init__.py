"""Write a component of a uio-observers co-simulation in Python (PROTOCOL.md, version 1).

A component is a step function and one call::

    import numpy as np
    from uio_component import run

    def setup(config):                 # once, before `ready`; returns the state
        return {"gain": config.params.get("gain", 1.0)}

    def step(k, inputs, state):        # inputs: one numpy array per `reads` entry
        return state["gain"] * inputs[0][:3]   # the `publishes.len` (here 3) values of sample k

    if __name__ == "__main__":
        run(step, setup)

The kit does what PROTOCOL.md asks of every component: the checks of how it was started (§1),
the run's iceoryx2 configuration (§2), the configuration file (§3), the services and the wire
format on iceoryx2's own Python binding (§4), the handshake and the step order (§5), and the
exit codes. Modules: `config` (start and configuration), `wire` (header, services, ports),
`loop` (`run` and the step order), `signals` (the scenario's signals, for plants).
"""

from .config import (EXIT_DIVERGED, EXIT_FAILED, EXIT_OK, EXIT_USAGE, PROTOCOL_VERSION,
                     ComponentExit, Config, Diverged, Model, Publish, Read, load_config, parse_config)
from .loop import TIMEOUT_S, Stepper, run
from .signals import Signal, Signals
from .wire import Bus, Header, Inlet, Outlet, ProtocolError, Received

__all__ = [
    "run", "Config", "Model", "Publish", "Read", "Diverged", "ComponentExit", "ProtocolError",
    "Header", "Bus", "Inlet", "Outlet", "Received", "Stepper", "Signal", "Signals",
    "load_config", "parse_config", "PROTOCOL_VERSION", "TIMEOUT_S",
    "EXIT_OK", "EXIT_USAGE", "EXIT_FAILED", "EXIT_DIVERGED",
]
