"""Training of VertexNet and the NRRT* network: Lightning, Hydra-instantiated objects, MLflow."""
