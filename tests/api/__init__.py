"""Tests of the top-level API: plan(), its strategy, plan_many, files, figures, the CLI."""
