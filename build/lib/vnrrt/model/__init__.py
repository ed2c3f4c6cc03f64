"""The VertexNet network (a fastai-style DynamicUnet over a ResNet encoder) and its focal loss."""

from vnrrt.model.loss import FocalLoss
from vnrrt.model.resnet import ResNetEncoder, load_torchvision_weights
from vnrrt.model.vertexnet import VertexNet

__all__ = ["FocalLoss", "ResNetEncoder", "VertexNet", "load_torchvision_weights"]
