# rostest integration tests: driver_node against a pseudo-terminal.
