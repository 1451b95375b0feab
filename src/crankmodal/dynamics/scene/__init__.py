"""The [dynamics] scene stage: keys, validation, building the model from a scene, the flexible-body tables."""
