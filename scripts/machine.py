"""What machine a measurement ran on, for the scripts that write figures into docs/."""


def cpu_model():
    """' of <the CPU's model>' as Linux names it, or nothing: the figures are this machine's
    (the bench's own line names it the same way)."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return " of " + " ".join(line.split(":", 1)[1].split())
    except OSError:
        pass
    return ""
