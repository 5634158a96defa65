"""Exit statuses of the ``cpm-nlp`` command: 0 solved, 1 a solve that did not succeed (the
result says why), 2 bad input, 70 an internal error (a bug), 130 Ctrl-C, 141 a reader that
closed stdout."""

EXIT_OK, EXIT_FAILED, EXIT_INPUT, EXIT_INTERNAL = 0, 1, 2, 70
#: Ctrl-C (128 + SIGINT), and a reader that closed our stdout (128 + SIGPIPE)
EXIT_INTERRUPTED, EXIT_BROKEN_PIPE = 130, 141
