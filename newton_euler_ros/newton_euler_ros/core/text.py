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

"""Text helpers of the loaders: clipping for messages, bounded file reads."""
import os

from .errors import RobotFileError

MAX_FILE_BYTES = 1024 * 1024     # robot and scene files are a few kB


def clip(text, limit=300):
    """Return str(text) cut to ``limit`` characters (for logs, messages)."""
    text = str(text)
    return text if len(text) <= limit else text[:limit] + '...'


class _Clipped(str):
    """A clipped repr that prints as itself under ``!r`` and ``str``."""

    def __repr__(self):
        return str(self)


def clip_repr(value, limit=200):
    """Return value, or its repr clipped to ``limit`` characters."""
    text = repr(value)
    if len(text) <= limit:
        return value
    return _Clipped(clip(text, limit))


def read_text(path, max_bytes=MAX_FILE_BYTES, what='file'):
    """
    Read a UTF-8 text file; every failure is a one-line RobotFileError.

    Refuses a directory, a file larger than ``max_bytes`` (without reading
    it), an empty file and bytes that are not UTF-8.
    """
    label = clip_repr(path)
    if os.path.isdir(path):
        raise RobotFileError(f'{label}: is a directory, not a {what}')
    try:
        size = os.path.getsize(path)
        if size > max_bytes:
            raise RobotFileError(f'{label}: {size} bytes, more than the '
                                 f'{max_bytes} accepted for a {what}')
        with open(path, 'rb') as fh:
            data = fh.read(max_bytes + 1)
    except OSError as exc:
        raise RobotFileError(f'{label}: cannot read: {exc.strerror}') \
            from None
    if len(data) > max_bytes:
        raise RobotFileError(f'{label}: more than the {max_bytes} bytes '
                             f'accepted for a {what}')
    try:
        text = data.decode('utf-8')
    except UnicodeDecodeError as exc:
        raise RobotFileError(f'{label}: not UTF-8 text (byte {exc.start}); '
                             f'is it a {what}?') from None
    if not text.strip():
        raise RobotFileError(f'{label}: the file is empty')
    return text
