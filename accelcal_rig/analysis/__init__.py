"""The paper's other experiments, on campaign files: how many positions, tilt accuracy, free cool-down."""
