"""A function run in a second process beside this one's work, so that a job uses the machine's second core
(``stereodepth demo`` runs its small Amaranth waveform run beside the full-size Verilator run)."""

__all__ = ["Background"]


def _call(conn, fn, args):
    try:
        conn.send(("value", fn(*args)))
    except BaseException as exc:                    # handed to the parent, which reports it
        conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        conn.close()


class Background:
    """``fn(*args)`` in a second process (forked), so that it uses the second core while this process works;
    :meth:`result` waits for its value, :meth:`stop` ends it. Where ``fork`` is not available it runs in
    :meth:`result`, after this process's work."""

    def __init__(self, fn, *args):
        import multiprocessing
        self.fn, self.args, self.proc = fn, args, None
        if "fork" in multiprocessing.get_all_start_methods():
            ctx = multiprocessing.get_context("fork")
            self.conn, child = ctx.Pipe(duplex=False)
            self.proc = ctx.Process(target=_call, args=(child, fn, args), daemon=True)
            self.proc.start()
            child.close()

    def result(self):
        """``fn``'s value; raises RuntimeError if it raised or its process died."""
        if self.proc is None:
            try:
                return self.fn(*self.args)
            except Exception as exc:
                raise RuntimeError(f"{type(exc).__name__}: {exc}") from exc
        try:
            kind, value = self.conn.recv()
        except EOFError:
            kind, value = "error", f"the process ended with exit status {self.proc.exitcode}"
        self.proc.join()
        if kind == "error":
            raise RuntimeError(value)
        return value

    def stop(self):
        if self.proc is not None and self.proc.is_alive():
            self.proc.terminate()
            self.proc.join()
