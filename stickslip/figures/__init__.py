"""The paper's figures: one module per figure, each registered as a ``figure`` plugin."""
