"""Tests of the project as a whole: import contract, docs, packaging, conventions, no narration."""
