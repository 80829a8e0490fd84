"""What the model gets wrong: whole-record comparison, misfit decision, mechanisms, model comparison."""
