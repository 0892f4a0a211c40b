"""Coverage-guided fuzzing of every reader (issue 17): the targets, the atheris runner, the CI slice."""
