"""`harness branches`: a scene run past its first undecidable state under every impact
law (`spread`: the branches and their spread; `text`: the terminal table; `plot`: the
figure)."""
