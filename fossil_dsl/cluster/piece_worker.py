"""A local process that checks pieces of split queries: `python -m
fossil_dsl.cluster.piece_worker`, one JSON object per line on stdin and stdout.

    in:  {"id": 3, "batch": "b1", "query": SMT-LIB, "region": SMT-LIB, "timeout": 10,
          "delta": null}                      a piece to check
         {"stop": "b1"}                       give up the pieces of that batch
    out: {"id": 3, "answer": {...}}           its answer (answer_json)

A child started by command, not a fork or a multiprocessing spawn, so nothing of the
parent is copied or re-imported (a user's script needs no `__main__` guard), and the
pieces travel as text.
"""
from __future__ import annotations

import json
import queue
import sys
import threading

from fossil_dsl.cluster.pieces import answer_json, check_piece, stopped_answer


class _Stops:
    """The batches given up, and an event per batch for the piece being checked."""

    def __init__(self):
        self.lock = threading.Lock()
        self.stopped: set[str] = set()
        self.events: dict[str, threading.Event] = {}

    def event(self, batch: str) -> threading.Event:
        with self.lock:
            event = self.events.setdefault(batch, threading.Event())
            if batch in self.stopped:
                event.set()
            return event

    def stop(self, batch: str) -> None:
        with self.lock:
            self.stopped.add(batch)
            self.events.setdefault(batch, threading.Event()).set()


def _read(tasks: queue.Queue, stops: _Stops) -> None:
    for line in sys.stdin:
        message = json.loads(line)
        if "stop" in message:
            stops.stop(message["stop"])
        else:
            tasks.put(message)
    tasks.put(None)  # the parent closed our stdin: finish


def main() -> None:
    tasks: queue.Queue = queue.Queue()
    stops = _Stops()
    threading.Thread(target=_read, args=(tasks, stops), daemon=True).start()
    while (task := tasks.get()) is not None:
        stop = stops.event(task["batch"])
        answer = stopped_answer() if stop.is_set() else \
            check_piece(task["query"], task["region"], task["timeout"], task["delta"], stop)
        sys.stdout.write(json.dumps({"id": task["id"], "answer": answer_json(answer)}) + "\n")
        sys.stdout.flush()


if __name__ == "__main__":
    main()
