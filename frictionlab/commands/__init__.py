"""One module per ``frictionlab`` subcommand."""
