# Copyright 2026 newton_euler_ros developers
#
# Licensed under the Apache License, Version 2.0 (the "License");
# you may not use this file except in compliance with the License.
# You may obtain a copy of the License at
#
#     http://www.apache.org/licenses/LICENSE-2.0
#
# Unless required by applicable law or agreed to in writing, software
# distributed under the License is distributed on an "AS IS" BASIS,
# WITHOUT WARRANTIES OR CONDITIONS OF ANY KIND, either express or implied.
# See the License for the specific language governing permissions and
# limitations under the License.

"""
Robots from URDF, and any model written back as URDF.

The modules, by what they hold:

- ``read``: reading URDF text safely (:func:`read_urdf_text`,
  :func:`parse_urdf`) and the model it describes (:func:`urdf_model`,
  :func:`load_urdf`, :func:`inspect_urdf`): the whole tree below a base
  link, or the chain to a tip;
- ``chain``: the chain from a base link to a tip link as the model (the
  fixed joints and the links off the chain merged);
- ``whole``: the whole tree below a base link as one model (no tip);
- ``tree``: what both share: the chain's ends, the path between them,
  the links rigidly attached to a link and their merged body;
- ``writer``: any model written as URDF (:func:`model_to_urdf`, for
  robot_state_publisher and RViz).

Here are their public names; the modules import one another (``read``
uses ``chain``, ``tree`` and ``whole``; ``chain`` and ``whole`` use
``tree``), never this package.
"""
from .read import (inspect_urdf, JOINT_TYPES, load_urdf, MAX_BYTES,
                   MAX_ELEMENTS, MAX_NAME, parse_urdf, read_urdf_text,
                   urdf_model)
from .writer import matrix_rpy, model_to_urdf

__all__ = [
    'JOINT_TYPES', 'MAX_BYTES', 'MAX_ELEMENTS', 'MAX_NAME', 'inspect_urdf',
    'load_urdf', 'matrix_rpy', 'model_to_urdf', 'parse_urdf',
    'read_urdf_text', 'urdf_model',
]
